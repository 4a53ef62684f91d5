"""SIGINT and SIGTERM during a command, sent to this very process (real signals)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from headsim.cli.interrupts import process_signals, sigterm_interrupts
from headsim.errors import clear_interrupted, interrupt_handler, interrupted

ROOT = Path(__file__).resolve().parents[2]
TESTS = str(ROOT / "tests")


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_inside_a_command_becomes_keyboardinterrupt_and_handlers_come_back(sig) -> None:
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    with pytest.raises(KeyboardInterrupt), sigterm_interrupts() as state:
        assert not state.signalled
        os.kill(os.getpid(), sig)
    assert state.signalled
    assert {s: signal.getsignal(s) for s in before} == before


def test_the_process_handlers_note_the_interrupt_and_ignore_the_file_size_signal() -> None:
    before = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGXFSZ)}
    try:
        with process_signals():
            assert signal.getsignal(signal.SIGTERM) is interrupt_handler
            assert signal.getsignal(signal.SIGXFSZ) is signal.SIG_IGN
            with pytest.raises(KeyboardInterrupt):
                os.kill(os.getpid(), signal.SIGTERM)
            assert interrupted()
        assert {s: signal.getsignal(s) for s in before} == before
    finally:
        clear_interrupted()


def test_an_interrupt_python_swallows_is_noted_silently_and_acted_on(capfd) -> None:
    # A SIGINT that lands inside a weakref callback (importlib's module-lock callback,
    # during a lazy import) raises KeyboardInterrupt there, which Python ignores.
    import weakref

    from headsim.errors import raise_if_interrupted

    class Thing:
        pass

    try:
        with process_signals():
            thing = Thing()
            ref = weakref.ref(thing, lambda _: os.kill(os.getpid(), signal.SIGINT))
            del thing  # the callback runs here; its KeyboardInterrupt is swallowed
            assert ref() is None
            assert interrupted()
            with pytest.raises(KeyboardInterrupt):
                raise_if_interrupted()
        assert not interrupted()  # acted on: the next command starts clean
    finally:
        clear_interrupted()
    err = capfd.readouterr().err
    assert "Exception ignored" not in err and "Traceback" not in err


# -- Ctrl-C during the test suite ---------------------------------------------------

PROBE = """
import time
from pathlib import Path

from headsim.cli import main


def test_drives_the_cli_in_process(tmp_path):
    Path({started!r}).touch()
    end, run = time.monotonic() + 10, 0
    while time.monotonic() < end:  # runs of about 2 s: the time is almost all inside main()
        run += 1
        main(["run", "quickstart", "--fast", "--out", str(tmp_path / str(run)), "--no-progress"])


def test_after_it():
    Path({after!r}).touch()
"""


def _interrupted_suite(tmp_path: Path, *plugins: str) -> tuple[int, str, bool]:
    """A pytest run over a test that drives the CLI in-process, SIGINT sent mid-command:
    pytest's exit code, its output, and whether the next test ran."""
    started, after = tmp_path / "started", tmp_path / "after"
    probe = tmp_path / "probe" / "test_probe.py"
    probe.parent.mkdir()
    probe.write_text(PROBE.format(started=str(started), after=str(after)))
    options = [arg for plugin in plugins for arg in ("-p", plugin)]
    config = ["--rootdir", str(ROOT), "-c", str(ROOT / "pyproject.toml"), "-p", "no:cacheprovider"]
    process = subprocess.Popen(
        [sys.executable, "-m", "pytest", "-q", *config, *options, str(probe)],
        cwd=ROOT,
        # The suite's conftest as a plugin (the probe lies outside tests/), its helpers on the path.
        env={**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl"), "PYTHONPATH": TESTS},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not started.exists():
            assert process.poll() is None and time.monotonic() < deadline, process.communicate()
            time.sleep(0.05)
        time.sleep(3.0)  # inside a command
        process.send_signal(signal.SIGINT)
        output, _ = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
    return process.returncode, output, after.exists()


def test_ctrl_c_stops_the_suite_not_only_the_command_it_drives(tmp_path: Path) -> None:
    code, output, next_ran = _interrupted_suite(tmp_path, "conftest")
    assert code == pytest.ExitCode.INTERRUPTED, output  # 2
    assert "KeyboardInterrupt" in output and not next_ran, output


def test_without_the_suites_setting_the_command_swallows_ctrl_c(tmp_path: Path) -> None:
    """The premise: main() alone turns Ctrl-C into 130 and the suite would run on."""
    code, output, next_ran = _interrupted_suite(tmp_path)
    assert next_ran and code != pytest.ExitCode.INTERRUPTED, output
