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
from headsim.runs.outputs import Outputs


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
    from headsim.studies.checks import BASELINE, TOLERANCES

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
    from headsim.runs.rerun_cli import recording_target

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
        batch = sweep.batch_options(spec, args.device)  # refused before it is announced
        if batch is not None:
            where += (
                f", batch back-end: up to {batch.worlds} heads per batch in lockstep, drawn "
                "through one OpenGL context at each head's own render fidelity"
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
    for record in sorted(outcome.failed, key=lambda r: r["index"]):
        reasons = [str(r) for r in record.get("failure_reasons") or [record.get("error", "")]]
        more = f" (and {len(reasons) - 2} more in jobs.jsonl)" if len(reasons) > 2 else ""
        why = "; ".join(reasons[:2]) + more
        print(printable(f"  job {record['index']} {record.get('status', '?')}: {why}"))
    rate = 60 * outcome.ran / outcome.wall_s if outcome.wall_s > 0 else 0.0
    speed = f" in {outcome.wall_s:.1f} s, {rate:.1f} jobs/min" if outcome.ran else ""
    print(
        f"{outcome.ran} jobs run ({outcome.skipped} already done){speed}; "
        f"{len(outcome.failed)} failed"
    )
    if batch is not None and outcome.rendered:
        drawn = outcome.rendered
        print(
            "batch back-end: lockstep heads through one OpenGL context: "
            f"{int(drawn.get('images', 0))} images, at most {int(drawn.get('largest', 0))} "
            "heads at once"
        )
    for kind, path in outcome.files.items():
        print(f"  {kind:18s} {path}")
    return 1 if outcome.failed else 0
