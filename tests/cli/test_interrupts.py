"""SIGINT and SIGTERM during a command, sent to this very process (real signals)."""

from __future__ import annotations

import os
import signal

import pytest

from headsim.cli.interrupts import process_signals, sigterm_interrupts
from headsim.errors import clear_interrupted, interrupt_handler, interrupted


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
