"""Progress on stderr: plain lines in logs (not a terminal), nothing with --quiet."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from pathlib import Path

from headsim.active.events import FixationStarted, PhaseStarted
from headsim.runs.events import Hub, RunFinished
from headsim.runs.progress import Counter, RunProgress, Status, time_left
from headsim.scenario.loading import load_scenario

DATA = Path(__file__).resolve().parents[1] / "data"


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ}
    env.setdefault("MUJOCO_GL", "egl")
    return subprocess.run(
        [sys.executable, "-m", "headsim.cli", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_time_left_from_the_rate_so_far() -> None:
    assert time_left(0, 10, 5.0) == "time left unknown"
    assert time_left(2, 10, 10.0) == "about 0:40 left"
    assert time_left(10, 10, 3.0) == "done"


def test_counter_prints_a_line_per_phase_and_at_most_one_per_interval_in_a_log() -> None:
    now = [0.0]
    stream = io.StringIO()
    counter = Counter(10, unit="fixations", stream=stream, interval_s=5.0, clock=lambda: now[0])
    progress = RunProgress(counter)
    hub = Hub([progress])
    hub.emit(PhaseStarted("calibration", None, None, {}))  # type: ignore[arg-type]
    for step in range(1, 5):
        hub.emit(FixationStarted(f"calibration {step}"))
    now[0] = 1.0  # within 5 s of the phase line: silent
    hub.emit(FixationStarted("calibration 5"))
    now[0] = 6.0
    hub.emit(FixationStarted("calibration 6"))  # step 5: five fixations done
    hub.emit(PhaseStarted("measurement", None, None, {}))  # type: ignore[arg-type]
    hub.emit(RunFinished(None))  # type: ignore[arg-type]
    lines = stream.getvalue().splitlines()
    assert lines == [
        "headsim: calibration: 0/10 fixations, 0.0/s, time left unknown",
        "headsim: calibration: 5/10 fixations, 0.8/s, about 0:06 left",
        "headsim: measurement: 6/10 fixations, 1.0/s, about 0:04 left",
        "headsim: finished: 10 fixations in 6.0 s",
    ]
    assert "\r" not in stream.getvalue()


def test_counter_lines_per_item_per_minute_with_notes() -> None:
    now = [0.0]
    stream = io.StringIO()
    counter = Counter(
        4,
        unit="jobs",
        name="headsim sweep",
        stream=stream,
        interval_s=0.0,
        per_minute=True,
        notes_in_lines=True,
        clock=lambda: now[0],
    )
    for done in range(1, 4):
        now[0] = 30.0 * done
        counter.update(note="(this one failed)" if done == 2 else "")
    counter.close()
    assert stream.getvalue().splitlines() == [
        "headsim sweep: 1/4 jobs, 2.0/min, about 1:30 left",
        "headsim sweep: 2/4 jobs (this one failed), 2.0/min, about 1:00 left",
        "headsim sweep: 3/4 jobs, 2.0/min, about 0:30 left",
        "headsim sweep: finished: 3 jobs in 90.0 s",
    ]


def test_counter_on_a_terminal_redraws_a_bar_with_count_rate_and_time_left() -> None:
    stream = io.StringIO()
    counter = Counter(10, unit="fixations", stream=stream, terminal=True)
    counter.phase("measurement")
    counter.update(4, "corner_3_0")
    counter.close(10)
    text = stream.getvalue()
    assert "\r" in text and text.endswith("\n")  # redrawn in place, left on screen at the end
    last = text.rstrip("\n").split("\r")[-1]
    assert last.startswith("measurement: 100%") and "10/10" in last and "fixations/s" in last
    assert "headsim: " not in text  # no plain lines on a terminal


def test_status_lines_carry_the_seconds_since_the_start() -> None:
    now = [0.0]
    stream = io.StringIO()
    status = Status("headsim bench", stream=stream, transient=True, clock=lambda: now[0])
    status("chessboard")  # transient, but not a terminal: plain lines
    now[0] = 12.25
    status("relative positioning")
    status.close()
    assert stream.getvalue().splitlines() == [
        "headsim bench: [    0.0 s] chessboard",
        "headsim bench: [   12.2 s] relative positioning",
    ]


def test_a_transient_status_on_a_terminal_is_one_line_redrawn_and_cleared() -> None:
    stream = io.StringIO()
    status = Status("headsim bench", stream=stream, transient=True, terminal=True)
    status("chessboard")
    status("relative positioning")
    status.close()
    status("realistic head")  # a new line after the one cleared
    status.close()
    shown = [part for part in stream.getvalue().split("\r") if part.strip()]
    assert shown[:2] == [
        "headsim bench: [00:00] chessboard",
        "headsim bench: [00:00] relative positioning",
    ]
    assert shown[-1] == "headsim bench: [00:00] realistic head"
    assert "\n" not in stream.getvalue()  # nothing left on screen


def test_run_and_sweep_print_plain_lines_in_a_log_and_nothing_when_quiet(tmp_path: Path) -> None:
    run = _cli("run", "quickstart", "--fast", "--out", str(tmp_path / "run"))
    assert run.returncode == 0, run.stderr
    assert "\r" not in run.stderr
    phases = re.findall(r"^headsim: (\w+): (\d+)/(\d+) fixations", run.stderr, re.M)
    assert [p[0] for p in phases][:2] == ["calibration", "measurement"]
    # The measurement starts once every calibration fixation has ended: all of them done.
    calibration = load_scenario("quickstart", fast=True).experiment.calibration
    assert calibration is not None
    assert (phases[0][1], phases[1][1]) == ("0", str(calibration.targets))
    assert re.search(r"^headsim: finished: \d+ fixations in [\d.]+ s$", run.stderr, re.M)

    sweep = _cli("sweep", str(DATA / "sweep_grid.toml"), "--out", str(tmp_path / "sweep"))
    assert sweep.returncode == 0, sweep.stderr
    assert "\r" not in sweep.stderr
    jobs = re.findall(r"^headsim sweep: (\d+)/(\d+) jobs, [\d.]+/min, (.*)$", sweep.stderr, re.M)
    total = int(jobs[0][1])
    assert [int(done) for done, _, _ in jobs] == list(range(1, total + 1))
    assert jobs[-1][2] == "done"
    assert re.search(rf"^headsim sweep: finished: {total} jobs in [\d.]+ s$", sweep.stderr, re.M)

    quiet = _cli("run", "quickstart", "--fast", "--quiet", "--out", str(tmp_path / "quiet"))
    assert quiet.returncode == 0 and quiet.stderr == ""
