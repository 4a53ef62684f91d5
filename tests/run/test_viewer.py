"""The recording in a real browser: Rerun's web viewer in headless Chromium (WebGL on SwiftShader).

Needs Debian's ``chromium`` (CI installs it: .ci/run).  The viewer draws into
a canvas, so the checks are pixel statistics of each view's region
(headsim.run.viewer_check.judge); the layout's text views are checked in the
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
from headsim.run import viewer_check

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parents[1] / "data"
#: Longest wait for the viewer to load and draw everything on two busy cores, s.
DRAW_TIMEOUT_S = 420.0


def _ready(image: np.ndarray) -> bool:
    return viewer_check.judge(image).ok


def _check(image: np.ndarray, png: Path) -> None:
    cv2.imwrite(str(png), cv2.cvtColor(image, cv2.COLOR_RGB2BGR))
    verdict = viewer_check.judge(image)
    assert verdict.ok, f"{png}: {verdict.problems} {verdict.figures}"


@pytest.fixture(scope="module")
def chromium() -> str:
    path = viewer_check.chromium_path()
    assert path is not None, "Chromium is needed: apt-get install -y chromium (CI: .ci/run)"
    return path


def test_the_judge_sees_an_error_panel_and_empty_views() -> None:
    # A real screenshot of Rerun 0.41's web viewer: one TextDocumentView over three
    # documents (the layout before issue 16) beside a good one.
    image = cv2.cvtColor(cv2.imread(str(DATA / "viewer_error_panel.png")), cv2.COLOR_BGR2RGB)
    verdict = viewer_check.judge(image)
    assert not verdict.ok
    assert verdict.figures["error_panel_px"] > 10_000
    assert any("error panel" in p for p in verdict.problems)
    assert any("head's bodies" in p for p in verdict.problems)
    assert any("camera 1" in p for p in verdict.problems)
    # A blank page is not a drawn viewer either.
    blank = np.full((*viewer_check.WINDOW[::-1], 3), 255, np.uint8)
    assert len(viewer_check.judge(blank).problems) >= 8


def test_the_quickstart_recording_draws_every_view_in_the_web_viewer(
    tmp_path: Path, chromium: str
) -> None:
    rrd = tmp_path / "recording.rrd"
    command = ["run", "quickstart", "--fast", "--out", str(tmp_path), "--rrd", str(rrd)]
    assert main([*command, "--no-progress"]) == 0
    with viewer_check.serve_file(rrd) as url:
        image = viewer_check.screenshot(
            url, ready=_ready, timeout_s=DRAW_TIMEOUT_S, executable=chromium
        )
    _check(image, tmp_path / "viewer.png")


def test_a_run_served_live_draws_every_view_in_the_web_viewer(
    tmp_path: Path, chromium: str
) -> None:
    web_port, grpc_port = viewer_check.free_port(), viewer_check.free_port()
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
        viewer_check.wait_for_port(web_port, 120, proc)
        started = time.monotonic()
        image = viewer_check.screenshot(
            viewer_check.viewer_url(web_port, grpc_port),
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
