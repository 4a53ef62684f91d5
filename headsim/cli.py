"""The ``headsim`` command line: ``run`` a scenario, ``list`` them, take a ``snapshot``, ...

Exit status (the contract of :mod:`headsim.errors`, held by every command): 0
everything succeeded; 1 a measurement or job failed; 2 bad input or arguments,
found before anything runs; 3 the environment (no GL backend, output not
writable, disk full, a dependency missing); 130 interrupted.  No traceback
reaches the user; ``--debug`` shows one.

This module imports only the standard library at the top, so that ``--help``,
``list`` and an interrupt during start-up are handled before numpy or mujoco load.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any

from headsim.errors import (
    EXIT_CODES_HELP,
    NO_SPACE_ERRNOS,
    BadInput,
    ExitCode,
    OutputNotWritable,
    clear_interrupted,
    guarded,
    interrupt_handler,
)
from headsim.run.outputs import Outputs
from headsim.sim import backend

#: Commands that never render: they run without any GL backend (so does ``--help``).
RENDER_FREE_COMMANDS = frozenset({"list"})
#: Options every command takes, anywhere on the command line.
GLOBAL_FLAGS = ("--debug", "--quiet")


def _snapshot(args: argparse.Namespace) -> int:
    from headsim.sim.settings import preset
    from headsim.sim.snapshot import take_snapshot

    settings = preset(args.preset, seed=args.seed)
    outputs = Outputs()
    try:
        out = outputs.directory(args.out, "--out")
        written = take_snapshot(
            out,
            args.scene,
            settings,
            neck_yaw=args.neck_yaw,
            neck_pitch=args.neck_pitch,
            eye=args.eye,
        )
    except ValueError as err:  # a pose beyond a joint's range, a bad scene
        raise BadInput(str(err)) from err
    finally:
        outputs.remove_empty_created()
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


#: The files ``headsim run`` writes in --out, besides the optional --rrd.
RUN_FILES = ("results.json", "summary.txt", "timing.json")


def _run(args: argparse.Namespace) -> int:
    from headsim.run.events import Subscriber
    from headsim.run.rerun_cli import recording_target
    from headsim.run.runner import run_scenario
    from headsim.run.serialise import results_payload
    from headsim.run.summary import summary_text
    from headsim.scenario.schema import load_scenario

    scenario = load_scenario(args.scenario, fast=args.fast, seed=args.seed)
    target = recording_target(args)  # a bad --url or port is bad input (exit 2)
    outputs = Outputs()
    try:
        # Every output, as the real file, before anything is rendered.
        out = outputs.directory(args.out, "--out")
        for name in RUN_FILES:
            outputs.file(out / name, "--out")
        rrd = outputs.file(target.rrd, "--rrd", atomic=False) if target.rrd else None
        observers: list[Subscriber] = []
        progress = _progress_observer(args, scenario.fixations, "fixations")
        if progress is not None:
            observers.append(progress)
        recorder = None
        if target.wanted:
            from headsim.run.recording import Recorder

            try:
                recorder = Recorder(rrd, scenario, target=target)
            except (OSError, RuntimeError) as err:
                if rrd is not None and _recording_failed(err):
                    raise _recording_disk_full(rrd, err) from err
                raise OutputNotWritable(f"--rrd: cannot write {rrd}: {err}") from err
            observers.append(recorder)
            if target.serve:
                print(f"serving the run live at {target.web_viewer_url}", flush=True)
        start = time.perf_counter()
        state = _Interrupted()
        try:
            with _sigterm_interrupts() as state:
                result = run_scenario(scenario, observers)
        except BaseException as err:
            if recorder is not None:
                with suppress(Exception):  # the writer may have died with the run
                    recorder.close()
            if not (isinstance(err, KeyboardInterrupt) or state.signalled):
                if rrd is not None and _recording_failed(err):
                    raise _recording_disk_full(rrd, err) from err
                raise
            kept = f"; the recording so far is in {rrd}" if rrd is not None else ""
            print(f"\nheadsim: interrupted: nothing written to {out}{kept}", file=sys.stderr)
            return ExitCode.INTERRUPTED
        # --serve keeps the stream open after a finished run; it is closed after serving.
        if recorder is not None and not target.serve:
            _close_recorder(recorder, rrd)
        wall = time.perf_counter() - start
        text = summary_text(result)
        _write_all(
            {
                out / "results.json": results_payload(result),
                out / "summary.txt": text + "\n",
                out / "timing.json": {
                    "scenario": scenario.name,
                    "fast": scenario.fast,
                    "wall_s": wall,
                    "phases_s": result.timing_s,
                    "renders": result.renders,
                    "rendered_frames": result.rendered_frames,
                    "windows": result.windows,
                    "rrd_bytes": rrd.stat().st_size if rrd is not None else None,
                },
            }
        )
    finally:
        outputs.remove_empty_created()
    print(text)
    print(f"\nwall time {wall:.1f} s; results in {out / 'results.json'} (summary.txt, timing.json)")
    if rrd is not None:
        print(f"recording {rrd} ({_size(rrd)}): open it with  rerun {rrd}")
    if recorder is not None and target.serve:
        _serve_until_interrupted(recorder, target.web_viewer_url)
    return 0 if result.ok else 1


def _progress_observer(args: argparse.Namespace, total: int, unit: str) -> Any:
    """The run's progress on stderr: a bar on a terminal, plain lines otherwise; none when quiet."""
    if getattr(args, "no_progress", False) or getattr(args, "quiet", False):
        return None
    from headsim.run.progress import Counter, RunProgress

    return RunProgress(Counter(total, unit=unit))


def _write_all(files: dict[Path, object]) -> None:
    """Write the result files atomically; on a full disk remove the ones this call wrote."""
    from headsim.run.outputs import disk_full
    from headsim.run.results import write_json_atomic, write_text_atomic

    written: list[Path] = []
    for path, content in files.items():
        data = content if isinstance(content, str) else None
        try:
            if data is not None:
                write_text_atomic(path, data)
            else:
                write_json_atomic(path, content)
        except OSError as err:
            for done in written:
                done.unlink(missing_ok=True)
            if err.errno in NO_SPACE_ERRNOS:
                size = len(data.encode()) if data is not None else _json_size(content)
                raise disk_full(path, size, err) from err
            raise OutputNotWritable(f"cannot write {path}: {err.strerror or err}") from err
        written.append(path)


def _json_size(payload: object) -> int:
    import json

    from headsim.run.results import to_jsonable

    return len(json.dumps(to_jsonable(payload), indent=2).encode()) + 1


#: What Rerun's file writer says when a write found no space (ENOSPC, EFBIG).
_NO_SPACE_TEXTS = ("os error 28", "os error 27", "no space left", "file too large", "file-writer")


def _recording_failed(err: BaseException) -> bool:
    """Whether ``err`` is Rerun's file writer giving up for lack of space (or the size limit)."""
    if isinstance(err, OSError):
        return err.errno in NO_SPACE_ERRNOS
    text = f"{err} {err.__cause__ or ''}".lower()
    return isinstance(err, RuntimeError) and any(t in text for t in _NO_SPACE_TEXTS)


def _recording_disk_full(rrd: Path, err: BaseException) -> Exception:
    from headsim.run.outputs import disk_full

    size = rrd.stat().st_size if rrd.is_file() else None
    return disk_full(rrd, None, err if isinstance(err, OSError) else None, written_bytes=size)


def _close_recorder(recorder, rrd: Path | None) -> None:
    """Close the recording as far as Rerun allows; a writer that already died is no new error."""
    try:
        recorder.close()
    except Exception as err:  # the file writer already failed: reported by the caller
        if rrd is not None and _recording_failed(err):
            raise _recording_disk_full(rrd, err) from err
        raise


def _calibrate(args: argparse.Namespace) -> int:
    from headsim.active.calibration_file import head_hash, write_calibration
    from headsim.run.runner import calibrate_scenario
    from headsim.run.serialise import calibration_block
    from headsim.scenario.schema import ScenarioError, load_scenario

    scenario = load_scenario(args.scenario, fast=args.fast, seed=args.seed)
    spec = scenario.experiment.calibration
    if spec is None or spec.source is not None:
        raise ScenarioError(
            str(scenario.path),
            "experiment.calibration",
            "no calibration to run" if spec is None else "it reads a calibration file itself",
            "an [experiment.calibration] table with targets (e.g. the quickstart scenario)",
        )
    out = Path(args.out)
    if out.is_dir():
        raise ScenarioError("--out", "", f"{out} is a directory", "a file path, e.g. head.json")
    outputs = Outputs()
    out = outputs.file(out, "--out")  # writable, as the real file, before anything renders
    observers = []
    progress = _progress_observer(args, spec.targets, "ball positions")
    if progress is not None:
        observers.append(progress)
    start = time.perf_counter()
    with _sigterm_interrupts():
        try:
            report = calibrate_scenario(scenario, observers)
        except KeyboardInterrupt:
            print(f"\nheadsim: interrupted: nothing written to {out}", file=sys.stderr)
            return 130
    wall = time.perf_counter() - start
    if progress is not None:
        progress.counter.close(report.fixated)
    if not report.ok or report.knowledge is None:
        print(
            f"headsim: calibration failed: {report.status_text}; nothing written", file=sys.stderr
        )
        return 1
    try:
        write_calibration(
            out, scenario.settings, calibration_block(report), scenario.name, scenario.seed
        )
    except OSError as err:
        raise OutputNotWritable(f"cannot write {out}: {err.strerror or err}") from err
    alpha, std = report.alpha_e_rad, report.alpha_e_std_rad
    assert alpha is not None and std is not None and report.rendered_frames is not None
    print(
        f"{scenario.name}{' (fast)' if scenario.fast else ''}: {report.fixated} of "
        f"{report.targets} ball positions fixated, {report.renders} renders "
        f"({report.rendered_frames:.1f} full frames of pixels) in {wall:.1f} s"
    )
    for index in (0, 1):
        print(f"  alpha_e{index + 1} = {alpha[index]:+.5f} rad (std {std[index]:.1e})")
    known = report.knowledge
    print(f"  v0 = {known.v0_px} px; kx/ky = {known.kx_over_ky}")
    print(f"head {head_hash(scenario.settings)[:12]}; written to {out}")
    print(f'use it with  [experiment.calibration] from = "{out.resolve()}"')
    return 0


def _reproduce(args: argparse.Namespace) -> int:
    from headsim.studies import reproduce

    try:
        with _sigterm_interrupts():  # SIGTERM too leaves the report so far
            return reproduce.main(args)
    except reproduce.ReproduceError as err:
        raise BadInput(str(err)) from err


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
    from headsim.scenario.schema import SCENARIOS_DIR, describe_scenarios

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
    from headsim.studies import study

    outputs = Outputs()
    try:
        outputs.directory(args.out, "--out")  # before hours of calibration, not after
        return study.run(args)
    finally:
        outputs.remove_empty_created()


def _bench(args: argparse.Namespace) -> int:
    from headsim.studies import bench

    args.baseline = args.baseline or str(bench.BASELINE)
    args.tolerances = args.tolerances or str(bench.TOLERANCES)
    outputs = Outputs()
    try:
        if args.json:
            outputs.file(args.json, "--json")
        if args.update_baseline:
            outputs.file(args.baseline, "--baseline")
        return bench.main(args)
    finally:
        outputs.remove_empty_created()


def _sweep(args: argparse.Namespace) -> int:
    from headsim.studies import sweep

    spec = sweep.load_sweep(args.sweep)
    from headsim.run.rerun_cli import recording_target

    target = recording_target(args, per_job=True)
    outputs = Outputs()
    try:
        outputs.directory(args.out, "--out")  # before anything is printed or run
        print(f"sweep {spec.path.name}: {spec.description}")
        print(
            f"  {len(spec.jobs)} jobs of {Path(spec.scenario).stem}{' (fast)' if spec.fast else ''}"
        )
        where = (
            f"Dask at {args.scheduler}" if args.scheduler else f"{args.workers} local process(es)"
        )
        print(f"  running on {where}; log {Path(args.out) / 'jobs.jsonl'}", flush=True)
        with _sigterm_interrupts():
            try:
                outcome = sweep.run_sweep(
                    spec,
                    args.out,
                    workers=args.workers,
                    scheduler=args.scheduler,
                    progress=not (args.no_progress or args.quiet),
                    recording=target if target.wanted else None,
                )
            except KeyboardInterrupt:
                print(
                    "\ninterrupted: finished jobs are in jobs.jsonl; run again to resume",
                    file=sys.stderr,
                )
                return ExitCode.INTERRUPTED
    finally:
        outputs.remove_empty_created()
    print(sweep.summary_table(spec, outcome.records.values()))
    rate = 60 * outcome.ran / outcome.wall_s if outcome.wall_s > 0 else 0.0
    print(
        f"{outcome.ran} jobs run ({outcome.skipped} already done) in {outcome.wall_s:.1f} s, "
        f"{rate:.1f} jobs/min; {len(outcome.failed)} failed"
    )
    for kind, path in outcome.files.items():
        print(f"  {kind:18s} {path}")
    return 1 if outcome.failed else 0


def _positive_int(text: str) -> int:
    """An argparse type: an integer >= 1 (a bad one is a usage error, exit 2)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not allowed (allowed: an integer >= 1)")
    return value


def build_parser(with_study: bool = True) -> argparse.ArgumentParser:
    """The command line; ``with_study``: with the study's options (imports the study)."""
    from headsim.sim import names
    from headsim.sim.settings import PRESETS

    parser = argparse.ArgumentParser(
        prog="headsim",
        description="MuJoCo testbed for vergence-based active stereo vision on humanoid heads.",
        epilog=EXIT_CODES_HELP,
    )
    parser.add_argument(
        "--debug", action="store_true", help="show the Python traceback of an error (any position)"
    )
    parser.add_argument(
        "--quiet",
        action="store_true",
        help="no progress output on stderr, only errors (any position)",
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = commands.add_parser(
        "run",
        help="run a scenario: print a summary, write results.json, optionally record to Rerun",
        description="Run the experiment of a scenario file in the simulator. Prints a summary "
        "table, writes DIR/results.json (and summary.txt, timing.json) and, with --rrd, a Rerun "
        "recording to replay with `rerun FILE`.",
    )
    run.add_argument(
        "scenario",
        metavar="SCENARIO",
        help="a scenario file (.toml) or the name of one in headsim/scenarios/ (see `headsim list`)",
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
    run.add_argument(
        "--no-progress", action="store_true", help="no progress on stderr (see also --quiet)"
    )
    from headsim.run.rerun_cli import add_recording_arguments

    add_recording_arguments(run)
    run.set_defaults(func=_run)

    calibrate = commands.add_parser(
        "calibrate",
        help="calibrate a head once (Sec. V) and write what it learnt to a file",
        description="Run only the Sec. V calibration of a scenario and write what the head "
        "learnt (initial directions, extended fit, standard errors) with the head settings it "
        "holds for (by a hash) to FILE. Scenarios use it with [experiment.calibration] from = "
        '"FILE" and refuse it for another head. Exit status: 0 written, 1 the calibration '
        "failed, 2 bad input, 3 FILE not writable, 130 interrupted.",
    )
    calibrate.add_argument(
        "scenario", metavar="SCENARIO", help="a scenario with [experiment.calibration]"
    )
    calibrate.add_argument("--out", required=True, metavar="FILE", help="the file to write")
    calibrate.add_argument("--seed", type=int, metavar="N", help="seed (default: the file's)")
    calibrate.add_argument("--fast", action="store_true", help="the scenario's fast variant")
    calibrate.add_argument("--no-progress", action="store_true", help="no progress bar")
    calibrate.set_defaults(func=_calibrate)

    repro = commands.add_parser(
        "reproduce",
        help="every Sec. VI experiment of the paper on one head, one calibration, one report",
        description="Calibrate the paper's head once, then run the initial directions, the "
        "chessboard, relative positioning, Tables V/VI against calibrated stereo with the "
        "focal length changed, and tracking, spread over workers. Writes DIR/report.md (the "
        "paper's figures beside ours, a verdict per row) with DIR/figures/*.png. Exit status: 0 "
        "all ran, 1 an experiment failed (the others are still reported), 2 bad input, 130 "
        "interrupted (the report so far stays).",
    )
    repro.add_argument("--out", required=True, metavar="DIR", help="output directory (created)")
    repro.add_argument("--fast", action="store_true", help="every experiment's fast variant")
    repro.add_argument(
        "--workers", type=int, default=1, metavar="N", help="worker processes (default 1)"
    )
    repro.add_argument("--sweeps", action="store_true", help="also the insensitivity sweeps (long)")
    repro.add_argument("--seed", type=int, metavar="N", help="seed (default 0)")
    repro.set_defaults(func=_reproduce)

    listing = commands.add_parser(
        "list",
        help="list the scenario files with one-line descriptions",
        description="List the scenario files (headsim/scenarios/*.toml) with their descriptions; "
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
        "--workers", type=_positive_int, default=1, metavar="N", help="local processes (default 1)"
    )
    sweep.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="run the jobs on this Dask scheduler instead (pip install 'headsim[dask]')",
    )
    sweep.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    from headsim.run.rerun_cli import add_recording_arguments

    add_recording_arguments(sweep, per_job=True)
    sweep.set_defaults(func=_sweep)

    study = commands.add_parser(
        "study", help="the insensitivity study: stereo against the active method, sweeps, plots"
    )
    if with_study:  # the study module (stereo, principal points) loads only for it
        from headsim.studies.study import STUDY_DESCRIPTION, add_arguments

        study.description = STUDY_DESCRIPTION
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
    for sub in commands.choices.values():  # every command states the exit-code contract
        sub.epilog = sub.epilog or EXIT_CODES_HELP
    return parser


def _command(argv: Sequence[str]) -> str | None:
    """The subcommand named on the command line (None for ``--help`` or none)."""
    if any(arg in ("-h", "--help") for arg in argv):
        return None
    return next((arg for arg in argv if not arg.startswith("-")), None)


def _main(argv: list[str], *, debug: bool, quiet: bool) -> int:
    command = _command(argv)
    if command is not None and command not in RENDER_FREE_COMMANDS:
        backend.check_backend()  # MUJOCO_GL was settled when headsim was imported
    args = build_parser(with_study="study" in argv).parse_args(argv)
    args.debug, args.quiet = debug, quiet
    return int(args.func(args))


@contextmanager
def _process_signals() -> Iterator[None]:
    """SIGINT and SIGTERM interrupt (exit 130, noted even where they surface as another
    error); the file-size limit fails a write (EFBIG) instead of killing the process."""
    clear_interrupted()

    previous: dict[int, object] = {}
    try:
        previous[signal.SIGTERM] = signal.signal(signal.SIGTERM, interrupt_handler)
        # A SIGINT the shell set to be ignored (a background job) stays ignored.
        if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
            previous[signal.SIGINT] = signal.signal(signal.SIGINT, interrupt_handler)
        if hasattr(signal, "SIGXFSZ"):
            previous[signal.SIGXFSZ] = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    except ValueError:  # not the main thread
        pass
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)  # type: ignore[arg-type]


def main(argv: Sequence[str] | None = None) -> int:
    """The ``headsim`` entry point: runs a command and returns its exit code (0, 1, 2, 3, 130)."""
    given = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in given
    quiet = "--quiet" in given
    rest = [arg for arg in given if arg not in GLOBAL_FLAGS]
    if not debug:  # Rerun's own log lines repeat errors that headsim reports in one line
        os.environ.setdefault("RUST_LOG", "off")
    with _process_signals():
        code = guarded(lambda: _main(rest, debug=debug, quiet=quiet), debug=debug)
    if code == ExitCode.INTERRUPTED and argv is None:
        # The process's own entry point, interrupted: its files are closed. Leave now, for
        # CPython ends a process by SIGINT at exit (status -2, not 130) once a
        # KeyboardInterrupt passed through an extension's PyRun_* call (pybind11's exec
        # while mujoco imports), even when headsim caught it.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(int(code))
    return code


if __name__ == "__main__":
    sys.exit(main())
