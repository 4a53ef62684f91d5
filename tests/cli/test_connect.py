"""``--connect`` without a viewer that answers, and signals meanwhile, through the real CLI.

Rerun's gRPC stream waits for ever on a viewer that is not there (and blocks SIGINT and
SIGTERM meanwhile): the command gives up after ``VIEWER_WAIT_S`` with exit 3 and one
line, and a signal ends it with 130 (SIGINT and SIGTERM alike).
"""

from __future__ import annotations

import signal
import socket
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from headsim.runs.rerun_cli import VIEWER_WAIT_S
from tests.cli.test_faults import CLI, _env, assert_one_line_error, headsim


def _url(port: int) -> str:
    return f"rerun+http://127.0.0.1:{port}/proxy"


@pytest.fixture
def closed_port() -> int:
    """A loopback port where nothing listens."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@pytest.fixture
def silent_port() -> Iterator[int]:
    """A loopback port that takes connections and never answers (a hung or foreign server)."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        sock.listen(16)
        yield int(sock.getsockname()[1])


def test_connect_with_no_viewer_is_exit_3_and_one_line_within_seconds(
    tmp_path: Path, closed_port: int
) -> None:
    out = tmp_path / "out"
    start = time.monotonic()
    result = headsim(
        "run", "quickstart", "--fast", "--out", str(out), "--connect", "--url",
        _url(closed_port), timeout=60,
    )  # fmt: skip
    took_s = time.monotonic() - start
    line = assert_one_line_error(result, 3, f"no Rerun viewer answered at 127.0.0.1:{closed_port}")
    assert f"within {VIEWER_WAIT_S:g} s" in line and "--rrd FILE" in line
    assert VIEWER_WAIT_S <= took_s < VIEWER_WAIT_S + 10, took_s
    assert not out.exists()


def test_a_viewer_that_never_answers_is_exit_3_not_a_hang(tmp_path: Path, silent_port: int) -> None:
    out = tmp_path / "out"
    result = headsim(
        "run", "quickstart", "--fast", "--out", str(out), "--connect", "--url",
        _url(silent_port), timeout=120,
    )  # fmt: skip
    assert_one_line_error(result, 3, "did not take the recording", f"within {VIEWER_WAIT_S:g} s")
    assert not (out / "results.json").exists()


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_streaming_to_a_silent_viewer_ends_the_run_with_130(
    tmp_path: Path, silent_port: int, sig: signal.Signals
) -> None:
    """SIGINT (Ctrl-C) and SIGTERM alike: exit 130 within a second or so, the stream stuck."""
    out = tmp_path / "out"
    command = [*CLI, "run", "quickstart", "--fast", "--out", str(out), "--connect"]
    process = subprocess.Popen(
        [*command, "--url", _url(silent_port)],
        env=_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stderr is not None
        for line in process.stderr:  # the run is under way, streaming
            if "headsim: calibration:" in line:
                break
        time.sleep(1.0)
        sent = time.monotonic()
        process.send_signal(sig)
        _, stderr = process.communicate(timeout=60)
        took_s = time.monotonic() - sent
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr and "interrupted" in stderr
    assert took_s < VIEWER_WAIT_S, took_s  # the stuck stream is not waited for in full
    assert not (out / "results.json").exists()
