"""Interrupts for the commands: SIGINT and SIGTERM stop a command cleanly (exit 130).

:func:`process_signals` holds for the whole process (installed by
:func:`headsim.cli.main`); :func:`sigterm_interrupts` turns both signals into
KeyboardInterrupt around a command's work, so that a stopped run still
closes its files; :func:`serve_until_interrupted` keeps ``--serve``'s viewer up.
Standard library only.
"""

from __future__ import annotations

import signal
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager

from headsim.errors import (
    clear_interrupted,
    interrupt_handler,
    note_interrupt,
)


class Interrupted:
    """Whether SIGINT or SIGTERM arrived (a KeyboardInterrupt raised inside a ctypes
    call, e.g. EGL's, reaches Python as a ctypes.ArgumentError instead)."""

    def __init__(self) -> None:
        self.signalled = False


@contextmanager
def sigterm_interrupts() -> Iterator[Interrupted]:
    """Turn SIGINT and SIGTERM into KeyboardInterrupt, so that a stopped run still closes its files."""
    state = Interrupted()

    def interrupt(signum: int, frame: object) -> None:
        state.signalled = True
        note_interrupt()
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


def serve_until_interrupted(recorder: object, url: str) -> None:
    """Keep --serve's viewer up after the run until Ctrl-C or SIGTERM; then close the recording."""
    print(f"serving the recording at {url} until Ctrl-C", flush=True)
    try:
        with sigterm_interrupts():
            while True:  # ends on Ctrl-C or SIGTERM only: serving is what the user asked for
                time.sleep(0.5)
    except KeyboardInterrupt:
        clear_interrupted()  # how serving ends: not an interrupted command
        print("stopped serving (interrupted)", file=sys.stderr)
    finally:
        recorder.close()  # type: ignore[attr-defined]


@contextmanager
def process_signals() -> Iterator[None]:
    """SIGINT and SIGTERM interrupt (exit 130, noted even where they surface as another
    error); the file-size limit fails a write (EFBIG) instead of killing the process."""
    clear_interrupted()
    hook = sys.unraisablehook

    def unraisable(info: sys.UnraisableHookArgs) -> None:
        # An interrupt raised inside a weakref callback or a finaliser is ignored by
        # Python: it is noted (headsim.errors.raise_if_interrupted acts on it), so
        # no "Exception ignored" traceback reaches the user.
        if not isinstance(info.exc_value, KeyboardInterrupt):
            hook(info)

    sys.unraisablehook = unraisable
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
        sys.unraisablehook = hook
        clear_interrupted()  # acted on by now (headsim.errors.guarded runs inside)
        for sig, handler in previous.items():
            signal.signal(sig, handler)  # type: ignore[arg-type]
