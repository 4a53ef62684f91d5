"""The study commands: ``headsim reproduce``, ``study``, ``bench`` and ``sweep``.

Each takes the parsed arguments and returns its exit code (:mod:`headsim.errors`);
:mod:`headsim.studies` loads inside them, not here.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from headsim.cli.interrupts import sigterm_interrupts
from headsim.errors import (
    BadInput,
    ExitCode,
    printable,
)
from headsim.run.outputs import Outputs


def reproduce_command(args: argparse.Namespace) -> int:
    from headsim.studies import reproduce

    try:
        with sigterm_interrupts():  # SIGTERM too leaves the report so far
            return reproduce.main(args)
    except reproduce.ReproduceError as err:
        raise BadInput(str(err)) from err


def study_command(args: argparse.Namespace) -> int:
    from headsim.studies import study

    outputs = Outputs()
    try:
        outputs.directory(args.out, "--out")  # before hours of calibration, not after
        return study.run(args)
    finally:
        outputs.remove_empty_created()


def bench_command(args: argparse.Namespace) -> int:
    from headsim.studies import bench
    from headsim.studies.bench_compare import BASELINE, TOLERANCES

    args.baseline = args.baseline or str(BASELINE)
    args.tolerances = args.tolerances or str(TOLERANCES)
    outputs = Outputs()
    try:
        if args.json:
            outputs.file(args.json, "--json")
        if args.update_baseline:
            outputs.file(args.baseline, "--baseline")
        return bench.main(args)
    finally:
        outputs.remove_empty_created()


def sweep_command(args: argparse.Namespace) -> int:
    from headsim.studies import sweep
    from headsim.studies.sweep_output import summary_table
    from headsim.studies.sweep_spec import load_sweep

    spec = load_sweep(args.sweep)
    from headsim.run.rerun_cli import recording_target

    target = recording_target(args, per_job=True)
    outputs = Outputs()
    try:
        outputs.directory(args.out, "--out")  # before anything is printed or run
        print(printable(f"sweep {spec.path.name}: {spec.description}"))
        print(
            printable(
                f"  {len(spec.jobs)} jobs of {Path(spec.scenario).stem}"
                f"{' (fast)' if spec.fast else ''}"
            )
        )
        where = (
            f"Dask at {args.scheduler}" if args.scheduler else f"{args.workers} local process(es)"
        )
        device = args.device or spec.batch.device
        if args.device and spec.backend != "batch":
            raise BadInput(
                f"--device {args.device}: the sweep's backend is {spec.backend!r}; "
                'allowed only with backend = "batch"'
            )
        if spec.backend == "batch":
            samples = spec.batch.samples_per_pixel
            where += (
                f", batch back-end: MuJoCo Warp on {device}, up to {spec.batch.worlds} heads "
                f"per batch, sub-pixel samples per axis: {samples or 'the head' + chr(39) + 's'}"
            )
        print(f"  running on {where}; log {Path(args.out) / 'jobs.jsonl'}", flush=True)
        with sigterm_interrupts():
            try:
                outcome = sweep.run_sweep(
                    spec,
                    args.out,
                    workers=args.workers,
                    scheduler=args.scheduler,
                    progress=not (args.no_progress or args.quiet),
                    recording=target if target.wanted else None,
                    device=args.device,
                )
            except KeyboardInterrupt:
                print(
                    "\ninterrupted: finished jobs are in jobs.jsonl; run again to resume",
                    file=sys.stderr,
                )
                return ExitCode.INTERRUPTED
    finally:
        outputs.remove_empty_created()
    print(printable(summary_table(spec, outcome.records.values())))
    rate = 60 * outcome.ran / outcome.wall_s if outcome.wall_s > 0 else 0.0
    print(
        f"{outcome.ran} jobs run ({outcome.skipped} already done) in {outcome.wall_s:.1f} s, "
        f"{rate:.1f} jobs/min; {len(outcome.failed)} failed"
    )
    if outcome.rendered:
        r = outcome.rendered
        mean = r.get("images", 0) / r["calls"] if r.get("calls") else 0.0
        print(
            f"batch back-end: MuJoCo Warp on {device} rendered {int(r.get('images', 0))} "
            f"images in {int(r.get('calls', 0))} calls (mean {mean:.1f}, largest "
            f"{int(r.get('largest', 0))}), {r.get('render_s', 0.0):.1f} s rendering"
        )
    for kind, path in outcome.files.items():
        print(f"  {kind:18s} {path}")
    return 1 if outcome.failed else 0
