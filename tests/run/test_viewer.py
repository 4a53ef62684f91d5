"""The recording in a real browser: Rerun's web viewer in headless Chromium (WebGL on SwiftShader).

Needs Debian's ``chromium`` (CI installs it: .ci/run).  The viewer draws into
a canvas, so the checks are pixel statistics of each view's region
(tests.run.viewer.judge.judge); the layout's text views are checked in the
layout itself in tests/run/test_recording.py.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from headsim.cli import main
from tests.run.viewer.browser import (
    chromium_path,
    free_port,
    screenshot,
    serve_file,
    viewer_url,
    wait_for_port,
)
from tests.run.viewer.judge import judge

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parents[1] / "data"
#: Longest wait for the viewer to load and draw everything on two busy cores, s.
DRAW_TIMEOUT_S = 420.0


def _ready(image: np.ndarray) -> bool:
    return judge(image).ok


def _check(image: np.ndarray, png: Path) -> None:
    cv2.imwrite(str(png), cv2.cvtColor(image, cv2.COLOR_RGB2BGR))
    verdict = judge(image)
    assert verdict.ok, f"{png}: {verdict.problems} {verdict.figures}"


@pytest.fixture(scope="module")
def chromium() -> str:
    path = chromium_path()
    assert path is not None, "Chromium is needed: apt-get install -y chromium (CI: .ci/run)"
    return path


def test_the_quickstart_recording_draws_every_view_in_the_web_viewer(
    tmp_path: Path, chromium: str
) -> None:
    rrd = tmp_path / "recording.rrd"
    command = ["run", "quickstart", "--fast", "--out", str(tmp_path), "--rrd", str(rrd)]
    assert main([*command, "--no-progress"]) == 0
    with serve_file(rrd) as url:
        image = screenshot(url, ready=_ready, timeout_s=DRAW_TIMEOUT_S, executable=chromium)
    _check(image, tmp_path / "viewer.png")


def test_a_run_served_live_draws_every_view_in_the_web_viewer(
    tmp_path: Path, chromium: str
) -> None:
    web_port, grpc_port = free_port(), free_port()
    command = [
        sys.executable,
        "-m",
        "headsim.cli",
        "run",
        "quickstart",
        "--fast",
        "--out",
        str(tmp_path / "out"),
        "--serve",
        "--web-port",
        str(web_port),
        "--grpc-port",
        str(grpc_port),
        "--no-progress",
    ]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        command, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        # The browser opens the viewer while the run is still going: it streams live.
        wait_for_port(web_port, 120, proc)
        started = time.monotonic()
        image = screenshot(
            viewer_url(web_port, grpc_port),
            ready=_ready,
            timeout_s=DRAW_TIMEOUT_S,
            executable=chromium,
        )
        assert proc.poll() is None, "the run stopped serving by itself"
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    _check(image, tmp_path / "viewer_live.png")
    assert proc.returncode == 0, err
    assert "serving the run live at http://127.0.0.1:" in out
    assert "stopped serving" in err
    assert (tmp_path / "out" / "results.json").exists()
    assert time.monotonic() - started < DRAW_TIMEOUT_S + 60
