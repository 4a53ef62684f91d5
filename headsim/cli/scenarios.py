"""The scenario commands: ``headsim run``, ``calibrate`` and ``list``.

Each takes the parsed arguments and returns its exit code (:mod:`headsim.errors`);
the simulator, the runner and the scenario reader load inside them, not here.
"""

from __future__ import annotations

import argparse
import sys
import time
from contextlib import suppress
from pathlib import Path
from typing import Any

from headsim.cli.interrupts import Interrupted, serve_until_interrupted, sigterm_interrupts
from headsim.cli.writing import (
    close_recorder,
    file_size,
    recording_disk_full,
    recording_failed,
    write_all,
)
from headsim.errors import (
    ExitCode,
    OutputNotWritable,
    printable,
    raise_if_interrupted,
)
from headsim.runs.outputs import Outputs

#: The files ``headsim run`` writes in --out, besides the optional --rrd.
RUN_FILES = ("results.json", "summary.txt", "timing.json")


def run_command(args: argparse.Namespace) -> int:
    from headsim.codec import encode
    from headsim.runs.events import Subscriber
    from headsim.runs.rerun_cli import recording_target
    from headsim.runs.runner import run_scenario
    from headsim.runs.serialise import results_payload
    from headsim.runs.summary import summary_text
    from headsim.scenario.loading import load_scenario
    from headsim.scenario.tables import ScenarioError

    head = getattr(args, "head", None)
    if head is not None and Path(head).is_file():
        head = str(Path(head).resolve())  # a flag's path is the shell's, not the file's
    overrides = None if head is None else {"head.model": head}
    try:
        scenario = load_scenario(args.scenario, fast=args.fast, seed=args.seed, overrides=overrides)
    except ScenarioError as err:
        if overrides is None or err.field != "head.model":
            raise
        raise ScenarioError("--head", "", err.problem, err.allowed) from None
    target = recording_target(args)  # a bad --url or port is bad input (exit 2)
    raise_if_interrupted()  # an interrupt swallowed while loading: nothing written yet
    outputs = Outputs()
    try:
        # Every output, as the real file, before anything is rendered.
        out = outputs.directory(args.out, "--out")
        for name in RUN_FILES:
            outputs.file(out / name, "--out")
        rrd = outputs.file(target.rrd, "--rrd", atomic=False) if target.rrd else None
        mcap_path = getattr(args, "mcap", None)
        mcap = outputs.file(Path(mcap_path), "--mcap", atomic=False) if mcap_path else None
        observers: list[Subscriber] = []
        progress = progress_observer(args, scenario.fixations, "fixations")
        if progress is not None:
            observers.append(progress)
        recorder = None
        if target.wanted:
            from headsim.runs.recording import Recorder

            try:
                recorder = Recorder(rrd, scenario, target=target)
            except (OSError, RuntimeError) as err:
                if rrd is not None and recording_failed(err):
                    raise recording_disk_full(rrd, err) from err
                raise OutputNotWritable(f"--rrd: cannot write {rrd}: {err}") from err
            observers.append(recorder)
            if target.serve:
                print(f"serving the run live at {target.web_viewer_url}", flush=True)
        mcap_run = None
        if mcap is not None:
            from headsim.runs.mcap_run import McapRun

            try:
                mcap_run = McapRun(mcap)
            except OSError as err:
                raise OutputNotWritable(f"--mcap: cannot write {mcap}: {err}") from err
            observers.append(mcap_run)
        start = time.perf_counter()
        state = Interrupted()
        try:
            with sigterm_interrupts() as state:
                result = run_scenario(scenario, observers)
        except BaseException as err:
            if recorder is not None:
                with suppress(Exception):  # the writer may have died with the run
                    recorder.close()
            if mcap_run is not None:
                with suppress(Exception):
                    mcap_run.close()
            if not (isinstance(err, KeyboardInterrupt) or state.signalled):
                if rrd is not None and recording_failed(err):
                    raise recording_disk_full(rrd, err) from err
                raise
            kept = f"; the recording so far is in {rrd}" if rrd is not None else ""
            print(f"\nheadsim: interrupted: nothing written to {out}{kept}", file=sys.stderr)
            return ExitCode.INTERRUPTED
        # --serve keeps the stream open after a finished run; it is closed after serving.
        if recorder is not None and not target.serve:
            close_recorder(recorder, rrd)
        if mcap_run is not None:
            mcap_run.close()
        wall = time.perf_counter() - start
        text = summary_text(result, getattr(args, "head", None))
        write_all(
            {
                out / "results.json": results_payload(result),
                out / "summary.txt": text + "\n",
                out / "timing.json": {
                    "scenario": scenario.name,
                    "fast": scenario.fast,
                    "wall_s": wall,
                    "phases_s": result.timing_s,
                    "render_counts": encode(result.renders),
                    "rendered_frames": result.rendered_frames,
                    "rrd_bytes": rrd.stat().st_size if rrd is not None else None,
                },
            }
        )
    finally:
        outputs.remove_empty_created()
    print(printable(text))
    print(
        printable(
            f"\nwall time {wall:.1f} s; results in {out / 'results.json'} (summary.txt, timing.json)"
        )
    )
    if rrd is not None:
        print(printable(f"recording {rrd} ({file_size(rrd)}): open it with  rerun {rrd}"))
    if mcap is not None:
        print(printable(f"MCAP recording {mcap} ({file_size(mcap)}): ROS 2 messages"))
    if recorder is not None and target.serve:
        serve_until_interrupted(recorder, target.web_viewer_url)
    return 0 if result.ok else 1


def progress_observer(args: argparse.Namespace, total: int, unit: str) -> Any:
    """The run's progress on stderr: a bar on a terminal, plain lines otherwise; none when quiet."""
    from headsim.runs.progress import Counter, RunProgress

    if getattr(args, "no_progress", False) or getattr(args, "quiet", False):
        return None
    return RunProgress(Counter(total, unit=unit))


def calibrate_command(args: argparse.Namespace) -> int:
    from headsim.active.calibration_file import head_hash, write_calibration
    from headsim.runs.runner import calibrate_scenario
    from headsim.scenario.loading import load_scenario
    from headsim.scenario.tables import ScenarioError

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
    progress = progress_observer(args, spec.targets, "ball positions")
    if progress is not None:
        observers.append(progress)
    start = time.perf_counter()
    with sigterm_interrupts():
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
        write_calibration(out, scenario.settings, report, scenario.name, scenario.seed)
    except OSError as err:
        raise OutputNotWritable(f"cannot write {out}: {err.strerror or err}") from err
    alpha, std = report.alpha_e_rad, report.alpha_e_std_rad
    assert alpha is not None and std is not None and report.rendered_frames is not None
    print(
        printable(
            f"{scenario.name}{' (fast)' if scenario.fast else ''}: {report.fixated} of "
            f"{report.targets} ball positions fixated, {report.renders.total} renders "
            f"({report.rendered_frames:.1f} full frames of pixels) in {wall:.1f} s"
        )
    )
    for index in (0, 1):
        print(f"  alpha_e{index + 1} = {alpha[index]:+.5f} rad (std {std[index]:.1e})")
    known = report.knowledge
    print(f"  v0 = {known.v0_px} px; kx/ky = {known.kx_over_ky}")
    print(printable(f"head {head_hash(scenario.settings)[:12]}; written to {out}"))
    print(printable(f'use it with  [experiment.calibration] from = "{out.resolve()}"'))
    return 0


def list_command(args: argparse.Namespace) -> int:
    from headsim.scenario.loading import SCENARIOS_DIR, describe_scenarios

    directory = Path(args.dir) if args.dir else SCENARIOS_DIR
    rows = list(describe_scenarios(directory))
    if not rows:
        print(printable(f"no scenario files (*.toml) in {directory}"))
        return 0
    print(printable(f"scenarios in {directory} (run one with: headsim run NAME --out DIR)"))
    shown = [tuple(printable(cell) for cell in row) for row in rows]
    name_width = max(len(name) for name, _, _ in shown)
    head_width = max(len("head"), *(len(head) for _, head, _ in shown))
    print(f"  {'name'.ljust(name_width)}  {'head'.ljust(head_width)}  description")
    for name, head, description in shown:
        print(f"  {name.ljust(name_width)}  {head.ljust(head_width)}  {description}")
    return 0 if all(head for _, head, _ in rows) else 2
