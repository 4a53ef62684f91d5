"""``headsim estimate LOG.mcap --mapping MAP.toml --out DIR``: targets estimated offline
from a recording (:mod:`headsim.head.offline`)."""

from __future__ import annotations

import argparse
import math

from headsim.errors import ExitCode, printable
from headsim.runs.outputs import Outputs


def estimate_command(args: argparse.Namespace) -> int:
    from headsim.cli.writing import write_all
    from headsim.head.offline import estimate_file, read_truth
    from headsim.runs.serialise import estimate_payload

    mapping, estimates, pairs = estimate_file(args.log, args.mapping)
    truth = None if args.truth is None else read_truth(args.truth)
    document = estimate_payload(
        str(args.log), estimates, pairs, mapping.belief, mapping.alpha_e_rad, truth
    )
    outputs = Outputs()
    try:
        out = outputs.directory(args.out, "--out")
        outputs.file(out / "results.json", "--out")
        write_all({out / "results.json": document})
    finally:
        outputs.remove_empty_created()
    print(printable(f"{document['stereo_pairs']} stereo pairs in {args.log}"))
    for m in document["measurements"]:
        if m["status"] != "ok":
            print(printable(f"  {m['name']}: FAILED, {m['status']}"))
            continue
        x, y, z = m["estimate_head_m"]
        pairs = round(m["details"]["pairs"])
        line = f"  {m['name']}: ({x:.4f}, {y:.4f}, {z:.4f}) m in H from {pairs} pairs"
        error = m["error_m"]
        if error is not None and math.isfinite(error):
            line += f"; error {error * 1000:.2f} mm ({m['error_pct_of_depth']:.3f} % of depth)"
        print(printable(line))
    print(printable(f"results in {out / 'results.json'}"))
    return ExitCode.OK if document["status"] == "ok" else ExitCode.FAILED
