"""Progress on stderr: plain lines in logs (not a terminal), nothing with --quiet."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from pathlib import Path

from headsim.run.progress import LineProgress, time_left

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


def test_line_progress_prints_a_line_per_phase_and_at_most_one_per_interval() -> None:
    now = [0.0]
    stream = io.StringIO()
    progress = LineProgress(10, stream, interval_s=5.0, clock=lambda: now[0])
    progress.phase("calibration", None, None, None)
    for step in range(1, 5):
        now[0] = float(step)
        progress.step(step, "x")  # within 5 s of the phase line: silent
    now[0] = 6.0
    progress.step(5, "x")
    progress.phase("measurement", None, None, None)
    progress.finished(None)
    lines = stream.getvalue().splitlines()
    assert lines == [
        "headsim: calibration: 0/10 fixations, 0.0/s, time left unknown",
        "headsim: calibration: 5/10 fixations, 0.8/s, about 0:06 left",
        "headsim: measurement: 5/10 fixations, 0.8/s, about 0:06 left",
        "headsim: finished: 10 fixations in 6.0 s",
    ]
    assert "\r" not in stream.getvalue()


def test_run_and_sweep_print_plain_lines_in_a_log_and_nothing_when_quiet(tmp_path: Path) -> None:
    run = _cli("run", "quickstart", "--fast", "--out", str(tmp_path / "run"))
    assert run.returncode == 0, run.stderr
    assert "\r" not in run.stderr
    phases = re.findall(r"^headsim: (\w+): (\d+)/(\d+) fixations", run.stderr, re.M)
    assert [p[0] for p in phases][:2] == ["calibration", "measurement"]
    assert re.search(r"^headsim: finished: \d+ fixations in [\d.]+ s$", run.stderr, re.M)

    sweep = _cli("sweep", str(DATA / "sweep_grid.toml"), "--out", str(tmp_path / "sweep"))
    assert sweep.returncode == 0, sweep.stderr
    assert "\r" not in sweep.stderr
    jobs = re.findall(
        r"^headsim sweep: (\d+)/(\d+) jobs done, [\d.]+/min, (.*)$", sweep.stderr, re.M
    )
    total = int(jobs[0][1])
    assert [int(done) for done, _, _ in jobs] == list(range(1, total + 1))
    assert jobs[-1][2] == "about 0 s left"

    quiet = _cli("run", "quickstart", "--fast", "--quiet", "--out", str(tmp_path / "quiet"))
    assert quiet.returncode == 0 and quiet.stderr == ""
