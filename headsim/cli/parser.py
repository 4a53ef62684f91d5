"""The ``headsim`` command line's arguments: every command, its options and its help.

Imports only the standard library, :mod:`headsim.errors`, :mod:`headsim.version`
and the command modules at the top (they load their work inside), so that
``--help`` stays fast; :func:`build_parser` reads the scene names when called, and a given preset is
checked against the settings' list only then.
"""

from __future__ import annotations

import argparse

from headsim.cli.estimate import estimate_command
from headsim.cli.scenarios import calibrate_command, list_command, run_command
from headsim.cli.snapshot import snapshot_command
from headsim.cli.studies import bench_command, reproduce_command, study_command, sweep_command
from headsim.errors import (
    EXIT_CODES_HELP,
)
from headsim.version import __version__


def positive_int(text: str) -> int:
    """An argparse type: an integer >= 1 (a bad one is a usage error, exit 2)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not allowed (allowed: an integer >= 1)")
    return value


def preset_name(text: str) -> str:
    """An argparse type: a head preset's name (the settings load only for a given one)."""
    from headsim.sim.settings import PRESETS

    if text not in PRESETS:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a preset (allowed: {', '.join(sorted(PRESETS))})"
        )
    return text


def build_parser(with_study: bool = True) -> argparse.ArgumentParser:
    """The command line; ``with_study``: with the study's options (imports the study)."""
    from headsim.sim import names
    from headsim.sim.head_files import SHIPPED

    parser = argparse.ArgumentParser(
        prog="headsim",
        description="MuJoCo testbed for vergence-based active stereo vision on humanoid heads.",
        epilog=EXIT_CODES_HELP,
    )
    parser.add_argument(
        "--version", action="version", version=f"headsim {__version__}", help="print the version"
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
    run.add_argument(
        "--head",
        metavar="HEAD",
        help=f"run on another head: {', '.join(SHIPPED)} or an MJCF file's path (sets head.model)",
    )
    run.add_argument(
        "--no-progress", action="store_true", help="no progress on stderr (see also --quiet)"
    )
    run.add_argument(
        "--mcap",
        metavar="FILE",
        help="also record the run as ROS 2 messages in MCAP: images, CameraInfo, JointState, "
        "TF, commands, estimates (needs headsim[mcap])",
    )
    from headsim.runs.rerun_cli import add_recording_arguments

    add_recording_arguments(run)
    run.set_defaults(func=run_command)

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
    calibrate.set_defaults(func=calibrate_command)

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
    repro.set_defaults(func=reproduce_command)

    estimate = commands.add_parser(
        "estimate",
        help="estimate targets offline from any head's MCAP recording (ROS 2 messages)",
        description="Find the mapping's targets in every stereo pair of a recording (Ca1's "
        "image with Ca2's nearest in time, the joints interpolated to it), triangulate them "
        "with the head's belief and its cameras' CameraInfo, and write DIR/results.json. "
        "Topics, joint names, signs, belief and targets come from the mapping file "
        "(docs: how-to/real-head). Exit status: 0 every target estimated, "
        "1 a target was not, 2 bad input, 3 the mcap extra missing or DIR not writable.",
    )
    estimate.add_argument("log", metavar="LOG.mcap", help="the recording")
    estimate.add_argument(
        "--mapping", required=True, metavar="MAP.toml", help="topics, joints, belief, targets"
    )
    estimate.add_argument(
        "--truth", metavar="TRUTH.json", help="score against these points (name: [x, y, z] in H, m)"
    )
    estimate.add_argument("--out", required=True, metavar="DIR", help="output directory (created)")
    estimate.set_defaults(func=estimate_command)

    listing = commands.add_parser(
        "list",
        help="list the scenario files with one-line descriptions",
        description="List the scenario files (scenarios/*.toml) with their descriptions; "
        "a file that does not validate says why.",
    )
    listing.add_argument("--dir", metavar="DIR", help="another directory of scenario files")
    listing.set_defaults(func=list_command)

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
        "--preset",
        default="ideal",
        type=preset_name,
        help="camera preset (default: ideal; a wrong name is answered with the list)",
    )
    snap.add_argument(
        "--eye", type=float, default=0.0, help="eye-motor angle, rad, positive inward"
    )
    snap.add_argument("--neck-yaw", type=float, default=0.0, help="neck yaw, rad")
    snap.add_argument(
        "--neck-pitch", type=float, default=0.0, help="neck pitch, rad, positive looks up"
    )
    snap.add_argument("--seed", type=int, default=0, help="seed of the image noise")
    snap.set_defaults(func=snapshot_command)

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
    add_pool_arguments(sweep, "the jobs")
    sweep.add_argument(
        "--device",
        choices=("cpu", "cuda"),
        help="the batch back-end's device (backend = \"batch\"; default: the file's, else cpu)",
    )
    sweep.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    from headsim.runs.rerun_cli import add_recording_arguments

    add_recording_arguments(sweep, per_job=True)
    sweep.set_defaults(func=sweep_command)

    study = commands.add_parser(
        "study", help="the insensitivity study: stereo against the active method, sweeps, plots"
    )
    if with_study:  # its sweeps' names load the study (stereo, principal points): only for it
        add_study_arguments(study)
    study.set_defaults(func=study_command)

    bench = commands.add_parser(
        "bench",
        help="run the regression suite (or any benchmark case) and compare it with the baseline",
        description="Without options: run the regression cases (Model 2 on ideal and paper "
        "cameras, calibration, chessboard, areas, the paper scenarios' fast variants, estimator "
        "speed) and compare each metric with benchmarks/baseline.json within "
        "benchmarks/tolerances.json; exit status 1 on a regression beyond tolerance. Every "
        "benchmark is a case: --list shows them, --case NAME runs one (a figures case's script "
        "takes its own arguments after --), --all runs the regression cases and every figures "
        "case of minutes.",
    )
    bench.add_argument("--list", action="store_true", help="list every case and exit")
    bench.add_argument(
        "--case", action="append", metavar="NAME", help="run this case (repeatable; see --list)"
    )
    bench.add_argument(
        "--all", action="store_true", help="the regression cases, then every figures case"
    )
    bench.add_argument(
        "script_args", nargs="*", metavar="-- ARGS", help="a figures case's own arguments"
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
    bench.set_defaults(func=bench_command)
    for sub in commands.choices.values():  # every command states the exit-code contract
        sub.epilog = sub.epilog or EXIT_CODES_HELP
    return parser


def add_pool_arguments(command: argparse.ArgumentParser, what: str) -> None:
    """A campaign's pool (:mod:`headsim.studies.jobs`): local processes or a Dask scheduler."""
    command.add_argument(
        "--workers",
        type=positive_int,
        default=1,
        metavar="N",
        help=f"run {what} on N local processes (default 1)",
    )
    command.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help=f"run {what} on this Dask scheduler instead (pip install 'headsim[dask]')",
    )


STUDY_DESCRIPTION = (
    "Calibrated stereo against the active method: the Tables V/VI comparison, changes of "
    "focal length, principal point and distortion after calibration, and sweeps (depth, focal, "
    "principal, k1, noise, encoder), and the realistic head's error budget; writes CSV, JSON "
    "and PNG to --out."
)


def add_study_arguments(study: argparse.ArgumentParser) -> None:
    """``headsim study``'s description and options (loads the study's sweeps for their names)."""
    from headsim.studies.catalogue import SWEEPS

    study.description = STUDY_DESCRIPTION
    what = study.add_mutually_exclusive_group(required=True)
    what.add_argument(
        "--experiment",
        choices=["compare", "budget"],
        help="compare: the Tables V/VI comparison; budget: the realistic head's error budget "
        "(headsim.studies.error_budget; scenario realistic_field, whatever --preset)",
    )
    what.add_argument("--sweep", choices=sorted(SWEEPS), help="one sweep")
    what.add_argument(
        "--all", action="store_true", help="the comparison, every sweep and the error budget"
    )
    study.add_argument("--out", required=True, help="output directory (created if missing)")
    study.add_argument("--preset", default="paper", choices=["ideal", "paper"])
    study.add_argument("--seed", type=int, default=0)
    study.add_argument(
        "--fast", action="store_true", help="small calibrations and two values per sweep"
    )
    add_pool_arguments(study, "the conditions")
