"""The exit-code contract of the ``headsim`` command line, in one place.

Every command ends with one of these codes, and no Python traceback reaches the
user (``headsim --debug ...`` shows one):

====  ==================================================================
0     everything succeeded
1     a measurement or job failed (or an internal error, reported as one)
2     bad input or arguments, found before anything runs
3     the environment: no GL backend, output not writable, disk full, a
      dependency missing
130   interrupted (Ctrl-C or SIGTERM)
====  ==================================================================

Raise :class:`BadInput` or :class:`EnvironmentProblem` (or a subclass) anywhere
below a command; :func:`guarded` maps them, and any other exception, to a code
and one line on stderr.  New subcommands get this for free from ``cli.main``.

Text that comes from a file (a scenario's name, description, target names, keys)
reaches the terminal through :func:`printable`, so that a control character in it
is shown escaped and never acts on the user's terminal.
"""

from __future__ import annotations

import errno
import os
import select
import sys
import traceback
from collections.abc import Callable
from enum import IntEnum
from typing import TextIO

#: Characters shown escaped: C0 and C1 controls and DEL (not the newline), and the
#: bidirectional embeddings, overrides and isolates that reorder what follows them.
_UNPRINTABLE = {
    code: f"\\u{code:04x}"
    for code in (*range(0x20), *range(0x7F, 0xA0), *range(0x202A, 0x202F), *range(0x2066, 0x206A))
    if code != 0x0A
}


def printable(text: str) -> str:
    """``text`` for the terminal: each control character (but the newline) written as
    TOML and Python write it, ``\\u001b`` for ESC, so it shows and does nothing."""
    return text.translate(_UNPRINTABLE)


class ExitCode(IntEnum):
    """What ``headsim`` returns to the shell."""

    OK = 0
    FAILED = 1
    BAD_INPUT = 2
    ENVIRONMENT = 3
    INTERRUPTED = 130


#: What each code means, for the documentation's exit-code reference.
EXIT_MEANINGS: dict[ExitCode, str] = {
    ExitCode.OK: "everything succeeded",
    ExitCode.FAILED: "a measurement or job failed (or the calibration it needed, or an internal error)",
    ExitCode.BAD_INPUT: "bad input or arguments (a scenario or sweep file, an option), "
    "found before anything runs or is written",
    ExitCode.ENVIRONMENT: "the environment: no GL backend, output not writable, disk full "
    "(or `ulimit -f` reached), a dependency missing",
    ExitCode.INTERRUPTED: "interrupted (Ctrl-C or SIGTERM)",
}

#: The contract as text, for ``--help``.
EXIT_CODES_HELP = (
    "exit status: 0 everything succeeded; 1 a measurement or job failed; 2 bad input or "
    "arguments, found before anything runs; 3 the environment (no GL backend, output not "
    "writable, disk full, a dependency missing); 130 interrupted. No traceback unless --debug."
)


class HeadsimError(Exception):
    """An error whose message is meant for the user, with its exit code."""

    exit_code: ExitCode = ExitCode.FAILED


class JobFailed(HeadsimError, RuntimeError):
    """A measurement or job failed (exit 1); the message says which and why."""

    exit_code = ExitCode.FAILED


class BadInput(HeadsimError):
    """A file or an argument that cannot work; found before anything runs (exit 2)."""

    exit_code = ExitCode.BAD_INPUT


class EnvironmentProblem(HeadsimError):
    """The machine cannot do it: GL, permissions, disk space, a dependency (exit 3)."""

    exit_code = ExitCode.ENVIRONMENT


class OutputNotWritable(EnvironmentProblem):
    """An output file or directory cannot be created or written."""


class DiskFull(EnvironmentProblem):
    """A write ran out of space (ENOSPC) or into the file-size limit (EFBIG)."""


#: errno values that mean "no room to write".
NO_SPACE_ERRNOS = frozenset({errno.ENOSPC, errno.EFBIG, errno.EDQUOT})


def describe_os_error(err: OSError) -> str:
    """One line for an OSError: what failed, on which file, and why."""
    name = f" {err.filename}" if err.filename else ""
    reason = err.strerror or str(err)
    if err.errno in NO_SPACE_ERRNOS:
        return f"no space to write{name}: {reason} (free some space or write elsewhere)"
    return f"cannot use{name}: {reason}"


class _Signals:
    """Whether SIGINT or SIGTERM arrived in this process (see :func:`interrupt_handler`)."""

    received = False


def interrupt_handler(signum: int, frame: object) -> None:
    """A signal handler: note the interrupt, then raise KeyboardInterrupt.

    An interrupt that lands inside a C extension's import or a ctypes call reaches
    Python as another exception (ImportError "initialization failed",
    ctypes.ArgumentError); the note makes it exit 130 all the same.
    """
    _Signals.received = True
    raise KeyboardInterrupt


def clear_interrupted() -> None:
    """Forget an earlier interrupt (a new command starts)."""
    _Signals.received = False


def interrupted() -> bool:
    """Whether an interrupt arrived through :func:`interrupt_handler`."""
    return _Signals.received


def note_interrupt() -> None:
    """Note an interrupt (a handler of its own calls this before raising)."""
    _Signals.received = True


def raise_if_interrupted() -> None:
    """Raise KeyboardInterrupt if an interrupt arrived and was swallowed.

    Python ignores an exception raised in a weakref callback or a finaliser (it
    reports it as "Exception ignored in ..."); an interrupt that lands inside one,
    say importlib's module-lock callback during a lazy import, would otherwise let
    the command run on to the end.  Called where a command is about to write or
    render (the events hub, before --out is created)."""
    if _Signals.received:
        raise KeyboardInterrupt


def exit_code_for(err: BaseException) -> tuple[ExitCode, str]:
    """The exit code and the one-line message for an exception that ended a command."""
    if isinstance(err, KeyboardInterrupt) or interrupted():
        return ExitCode.INTERRUPTED, "interrupted"
    if isinstance(err, HeadsimError):
        return err.exit_code, str(err)
    if isinstance(err, OSError):
        return ExitCode.ENVIRONMENT, describe_os_error(err)
    if isinstance(err, MemoryError):
        return ExitCode.ENVIRONMENT, "out of memory"
    if isinstance(err, ImportError):
        missing = err.name or str(err)
        return (
            ExitCode.ENVIRONMENT,
            f"a dependency is missing: {missing} ({err}); reinstall headsim with pip",
        )
    if isinstance(err, RecursionError):
        return ExitCode.BAD_INPUT, "input nested too deeply to process"
    text = str(err) or type(err).__name__
    return (
        ExitCode.FAILED,
        f"internal error: {type(err).__name__}: {text} (run with --debug for the traceback)",
    )


def guarded(body: Callable[[], int], *, debug: bool = False, stream: TextIO | None = None) -> int:
    """Run ``body`` and return its exit code; an exception becomes a code and one line.

    ``SystemExit`` (argparse's usage errors, exit 2) passes through unchanged.
    With ``debug`` the traceback is printed too.
    """
    stream = sys.stderr if stream is None else stream
    try:
        code = int(body())
        if code != ExitCode.INTERRUPTED:
            raise_if_interrupted()  # swallowed on the way and never acted on: still 130
        return code
    except SystemExit:
        raise
    except BrokenPipeError as err:
        if not _stdout_gone():
            return _report(err, debug, stream)
        return int(ExitCode.OK)  # its reader stopped reading (``headsim list | head``)
    except BaseException as err:
        return _report(err, debug, stream)


def _stdout_gone() -> bool:
    """Whether standard output's reader has gone (a pipe with no reader polls as an
    error); if so, later writes go nowhere, so that the interpreter's last flush is quiet."""
    try:
        fd = sys.stdout.fileno()
        poller = select.poll()
        poller.register(fd, select.POLLOUT)
        if not any(events & select.POLLERR for _, events in poller.poll(0)):
            return False
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, fd)
        return True
    except (OSError, ValueError, AttributeError):  # no file behind it: not a pipe's end
        return False


def _report(err: BaseException, debug: bool, stream: TextIO) -> int:
    """Print ``err`` as one line (its traceback too with ``debug``); its exit code."""
    code, message = exit_code_for(err)
    if debug:
        traceback.print_exception(err, file=stream)
    try:
        print(
            f"headsim: {'' if code == ExitCode.INTERRUPTED else 'error: '}{printable(message)}",
            file=stream,
        )
        stream.flush()
    except (OSError, ValueError):  # stderr itself is gone
        pass
    return int(code)
