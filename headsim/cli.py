"""The ``headsim`` command line: ``run`` a scenario, ``list`` them, take a ``snapshot``.

Exit status: 0 when everything succeeded; 1 when a measurement (or the
calibration it needed) failed; 2 on bad input (a scenario file, an argument),
when nothing is run or written; 130 when interrupted.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from headsim import names
from headsim.settings import PRESETS, SettingsError, preset


def _snapshot(args: argparse.Namespace) -> int:
    from headsim.snapshot import take_snapshot

    settings = preset(args.preset, seed=args.seed)
    written = take_snapshot(
        args.out,
        args.scene,
        settings,
        neck_yaw=args.neck_yaw,
        neck_pitch=args.neck_pitch,
        eye=args.eye,
    )
    print(f"scene {args.scene!r}, preset {args.preset!r}: wrote")
    for kind, path in written.items():
        print(f"  {kind:9s} {path}")
    return 0


def _size(path: Path) -> str:
    size = path.stat().st_size
    return f"{size / 1e6:.1f} MB" if size >= 1e5 else f"{size / 1e3:.0f} kB"


class _Interrupted:
    """Whether SIGINT or SIGTERM arrived (a KeyboardInterrupt raised inside a ctypes
    call, e.g. EGL's, reaches Python as a ctypes.ArgumentError instead)."""

    def __init__(self) -> None:
        self.signalled = False


@contextmanager
def _sigterm_interrupts() -> Iterator[_Interrupted]:
    """Turn SIGINT and SIGTERM into KeyboardInterrupt, so that a stopped run still closes its files."""
    state = _Interrupted()

    def interrupt(signum: int, frame: object) -> None:
        state.signalled = True
        raise KeyboardInterrupt

    try:
        previous = {sig: signal.signal(sig, interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread
        yield state
        return
    try:
        yield state
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _run(args: argparse.Namespace) -> int:
    from headsim.report import results_payload, summary_text
    from headsim.results import write_json_atomic, write_text_atomic
    from headsim.runner import Observer, Progress, run_scenario
    from headsim.scenario import ScenarioError, load_scenario

    scenario = load_scenario(args.scenario, fast=args.fast, seed=args.seed)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ScenarioError("--out", "", f"{out} exists and is not a directory", "a directory")
    from headsim.rerun_cli import RecordingArgumentError, recording_target

    try:
        target = recording_target(args)
    except RecordingArgumentError as err:
        raise ScenarioError(err.field, "", err.message, err.allowed) from err
    rrd = target.rrd
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ScenarioError(
            "--out", "", f"cannot create {out}: {err.strerror}", "a writable directory"
        ) from err
    observers: list[Observer] = []
    if not args.no_progress and sys.stderr.isatty():
        observers.append(Progress(scenario.fixations, sys.stderr))
    recorder = None
    if target.wanted:
        from headsim.recording import Recorder

        try:
            recorder = Recorder(rrd, scenario, target=target)
        except OSError as err:
            raise ScenarioError(
                "--rrd", "", f"cannot write {rrd}: {err}", "a writable file path"
            ) from err
        observers.append(recorder)
        if target.serve:
            print(f"serving the run live at {target.web_viewer_url}", flush=True)
    start = time.perf_counter()
    state = _Interrupted()
    finished = False
    try:
        with _sigterm_interrupts() as state:
            result = run_scenario(scenario, observers)
        finished = True
    except BaseException as err:
        if not (isinstance(err, KeyboardInterrupt) or state.signalled):
            raise
        kept = f"; the recording so far is in {rrd}" if rrd is not None else ""
        print(f"\nheadsim: interrupted: nothing written to {out}{kept}", file=sys.stderr)
        return 130
    finally:
        # --serve keeps the stream open after a finished run; it is closed after serving.
        if recorder is not None and not (finished and target.serve):
            recorder.close()
    wall = time.perf_counter() - start
    text = summary_text(result)
    write_json_atomic(out / "results.json", results_payload(result))
    write_text_atomic(out / "summary.txt", text + "\n")
    write_json_atomic(
        out / "timing.json",
        {
            "scenario": scenario.name,
            "fast": scenario.fast,
            "wall_s": wall,
            "phases_s": result.timing_s,
            "renders": result.renders,
            "rrd_bytes": rrd.stat().st_size if rrd is not None else None,
        },
    )
    print(text)
    print(f"\nwall time {wall:.1f} s; results in {out / 'results.json'} (summary.txt, timing.json)")
    if rrd is not None:
        print(f"recording {rrd} ({_size(rrd)}): open it with  rerun {rrd}")
    if recorder is not None and target.serve:
        _serve_until_interrupted(recorder, target.web_viewer_url)
    return 0 if result.ok else 1


def _serve_until_interrupted(recorder: object, url: str) -> None:
    """Keep --serve's viewer up after the run until Ctrl-C or SIGTERM; then close the recording."""
    print(f"serving the recording at {url} until Ctrl-C", flush=True)
    try:
        with _sigterm_interrupts():
            while True:  # ends on Ctrl-C or SIGTERM only: serving is what the user asked for
                time.sleep(0.5)
    except KeyboardInterrupt:
        print("stopped serving (interrupted)", file=sys.stderr)
    finally:
        recorder.close()  # type: ignore[attr-defined]


def _list(args: argparse.Namespace) -> int:
    from headsim.scenario import SCENARIOS_DIR, describe_scenarios

    directory = Path(args.dir) if args.dir else SCENARIOS_DIR
    rows = list(describe_scenarios(directory))
    if not rows:
        print(f"no scenario files (*.toml) in {directory}")
        return 0
    print(f"scenarios in {directory} (run one with: headsim run NAME --out DIR)")
    width = max(len(name) for name, _ in rows)
    for name, description in rows:
        print(f"  {name.ljust(width)}  {description}")
    return 0 if all(not d.startswith("INVALID") for _, d in rows) else 2


def _study(args: argparse.Namespace) -> int:
    from headsim import study

    return study.run(args)


def _bench(args: argparse.Namespace) -> int:
    from headsim import bench

    args.baseline = args.baseline or str(bench.BASELINE)
    args.tolerances = args.tolerances or str(bench.TOLERANCES)
    return bench.main(args)


def _sweep(args: argparse.Namespace) -> int:
    from headsim import sweep

    spec = sweep.load_sweep(args.sweep)
    from headsim.rerun_cli import RecordingArgumentError, recording_target

    try:
        target = recording_target(args, per_job=True)
    except RecordingArgumentError as err:
        raise sweep.SweepError(err.field, "", err.message, err.allowed) from err
    print(f"sweep {spec.path.name}: {spec.description}")
    print(f"  {len(spec.jobs)} jobs of {Path(spec.scenario).stem}{' (fast)' if spec.fast else ''}")
    where = f"Dask at {args.scheduler}" if args.scheduler else f"{args.workers} local process(es)"
    print(f"  running on {where}; log {Path(args.out) / 'jobs.jsonl'}", flush=True)
    with _sigterm_interrupts():
        try:
            outcome = sweep.run_sweep(
                spec,
                args.out,
                workers=args.workers,
                scheduler=args.scheduler,
                progress=not args.no_progress,
                recording=target if target.wanted else None,
            )
        except KeyboardInterrupt:
            print(
                "\ninterrupted: finished jobs are in jobs.jsonl; run again to resume",
                file=sys.stderr,
            )
            return 130
    print(sweep.summary_table(spec, outcome.records.values()))
    rate = 60 * outcome.ran / outcome.wall_s if outcome.wall_s > 0 else 0.0
    print(
        f"{outcome.ran} jobs run ({outcome.skipped} already done) in {outcome.wall_s:.1f} s, "
        f"{rate:.1f} jobs/min; {len(outcome.failed)} failed"
    )
    for kind, path in outcome.files.items():
        print(f"  {kind:18s} {path}")
    return 1 if outcome.failed else 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="headsim",
        description="MuJoCo testbed for vergence-based active stereo vision on humanoid heads.",
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = commands.add_parser(
        "run",
        help="run a scenario: print a summary, write results.json, optionally record to Rerun",
        description="Run the experiment of a scenario file in the simulator. Prints a summary "
        "table, writes DIR/results.json (and summary.txt, timing.json) and, with --rrd, a Rerun "
        "recording to replay with `rerun FILE`. Exit status: 0 all measurements ok, 1 a "
        "measurement failed, 2 bad input (nothing run or written), 130 interrupted.",
    )
    run.add_argument(
        "scenario",
        metavar="SCENARIO",
        help="a scenario file (.toml) or the name of one in scenarios/ (see `headsim list`)",
    )
    run.add_argument("--out", required=True, metavar="DIR", help="output directory (created)")
    run.add_argument(
        "--seed",
        type=int,
        metavar="N",
        help="seed of image noise and random layouts (default: the file's seed)",
    )
    run.add_argument(
        "--fast", action="store_true", help="the scenario's fast variant (its [fast] table)"
    )
    run.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    from headsim.rerun_cli import add_recording_arguments

    add_recording_arguments(run)
    run.set_defaults(func=_run)

    listing = commands.add_parser(
        "list",
        help="list the scenario files with one-line descriptions",
        description="List the scenario files (scenarios/*.toml) with their descriptions; "
        "a file that does not validate says why.",
    )
    listing.add_argument("--dir", metavar="DIR", help="another directory of scenario files")
    listing.set_defaults(func=_list)

    snap = commands.add_parser(
        "snapshot",
        help="render both eye cameras and write PNGs and the ground truth as JSON",
        description="Pose the head, render both cameras, and write cam1.png, cam2.png, "
        "overview.png (true projections marked) and truth.json to --out.",
    )
    snap.add_argument("--out", required=True, help="output directory (created if missing)")
    snap.add_argument(
        "--scene",
        default="default",
        help=f"scene: {', '.join(sorted(names.SCENES))} or an MJCF path",
    )
    snap.add_argument(
        "--preset", default="ideal", choices=sorted(PRESETS), help="camera preset (default: ideal)"
    )
    snap.add_argument(
        "--eye", type=float, default=0.0, help="eye-motor angle, rad, positive inward"
    )
    snap.add_argument("--neck-yaw", type=float, default=0.0, help="neck yaw, rad")
    snap.add_argument(
        "--neck-pitch", type=float, default=0.0, help="neck pitch, rad, positive looks up"
    )
    snap.add_argument("--seed", type=int, default=0, help="seed of the image noise")
    snap.set_defaults(func=_snapshot)

    sweep = commands.add_parser(
        "sweep",
        help="run a parameter sweep (many scenario runs) locally or on a Dask cluster",
        description="Run every job of a sweep file (a grid or a seeded random sample over "
        "scenario fields). Jobs are appended to DIR/jobs.jsonl as they finish: run the same "
        "command again to resume. Writes DIR/aggregate.csv, aggregate.json and plots. Exit "
        "status 1 if a job failed, 2 on a bad sweep file.",
    )
    sweep.add_argument(
        "sweep", metavar="SWEEP", help="a sweep file (.toml), e.g. sweeps/focal.toml"
    )
    sweep.add_argument("--out", required=True, metavar="DIR", help="output directory (created)")
    sweep.add_argument(
        "--workers", type=int, default=1, metavar="N", help="local processes (default 1)"
    )
    sweep.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="run the jobs on this Dask scheduler instead (pip install 'headsim[dask]')",
    )
    sweep.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    from headsim.rerun_cli import add_recording_arguments

    add_recording_arguments(sweep, per_job=True)
    sweep.set_defaults(func=_sweep)

    from headsim.study import STUDY_DESCRIPTION, add_arguments

    study = commands.add_parser(
        "study",
        help="the insensitivity study: stereo against the active method, sweeps, plots",
        description=STUDY_DESCRIPTION,
    )
    add_arguments(study)
    study.set_defaults(func=_study)

    bench = commands.add_parser(
        "bench",
        help="run the regression suite and compare it with the stored baseline",
        description="Run a fixed suite (Model 2 on ideal and paper cameras, calibration, "
        "chessboard, areas, the paper scenarios' fast variants, estimator speed) and compare "
        "each metric with benchmarks/baseline.json within benchmarks/tolerances.json. Exit "
        "status 1 on a regression beyond tolerance.",
    )
    bench.add_argument("--seed", type=int, default=0, help="seed of the suite (default 0)")
    bench.add_argument("--json", metavar="FILE", help="also write the metrics to FILE")
    bench.add_argument("--baseline", default=None, metavar="FILE", help="baseline to compare with")
    bench.add_argument("--tolerances", default=None, metavar="FILE", help="per-metric tolerances")
    bench.add_argument(
        "--update-baseline", action="store_true", help="rewrite the baseline with these figures"
    )
    bench.add_argument(
        "--reason", help="why the baseline changes (required with --update-baseline)"
    )
    bench.set_defaults(func=_bench)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    from headsim.scenario import ScenarioError
    from headsim.sweep import SweepError

    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (SettingsError, ScenarioError, SweepError) as err:
        print(f"headsim: error: {err}", file=sys.stderr)
        return 2
    except ValueError as err:
        if args.command != "snapshot":
            raise
        print(f"headsim: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
