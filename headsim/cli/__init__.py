"""The ``headsim`` command line: ``run`` a scenario, ``list`` them, take a ``snapshot``, ...

Exit status (the contract of :mod:`headsim.errors`, held by every command): 0
everything succeeded; 1 a measurement or job failed; 2 bad input or arguments,
found before anything runs; 3 the environment (no GL backend, output not
writable, disk full, a dependency missing); 130 interrupted.  No traceback
reaches the user; ``--debug`` shows one.

This package imports only the standard library (and :mod:`headsim.errors`,
:mod:`headsim.runs.outputs`, :mod:`headsim.sim.backend`) at the top of its modules, so
that ``--help`` and ``list`` are answered before numpy or mujoco load; :func:`main`
imports the commands inside its guard, so that an interrupt during start-up is exit 130
and one line too.  The entry point is here (``headsim.cli:main``); one module per command
group: :mod:`~headsim.cli.scenarios` (run, calibrate, list), :mod:`~headsim.cli.studies`
(reproduce, study, bench, sweep), :mod:`~headsim.cli.snapshot`; the arguments in
:mod:`~headsim.cli.parser`.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

from headsim.errors import ExitCode

#: Commands that never render: they run without any GL backend (so does ``--help``).
RENDER_FREE_COMMANDS = frozenset({"list"})
#: Options every command takes, anywhere on the command line.
GLOBAL_FLAGS = ("--debug", "--quiet")
#: Whether :func:`main` called with ``argv`` (in-process) raises KeyboardInterrupt after an
#: interrupted command instead of returning 130: for callers that Ctrl-C must stop too (the
#: test suite sets it, so that Ctrl-C stops the suite, not just the command under test).
RAISE_INTERRUPTS = False


def _command(argv: Sequence[str]) -> str | None:
    """The subcommand named on the command line (None for ``--help`` or none)."""
    if any(arg in ("-h", "--help") for arg in argv):
        return None
    return next((arg for arg in argv if not arg.startswith("-")), None)


def _main(argv: list[str], *, debug: bool, quiet: bool) -> int:
    from headsim.cli.parser import build_parser
    from headsim.sim import backend

    command = _command(argv)
    if command is not None and command not in RENDER_FREE_COMMANDS:
        backend.check_backend()  # MUJOCO_GL was settled when headsim was imported
    args = build_parser(with_study="study" in argv).parse_args(argv)
    args.debug, args.quiet = debug, quiet
    return int(args.func(args))


def main(argv: Sequence[str] | None = None) -> int:
    """The ``headsim`` entry point: runs a command and returns its exit code (0, 1, 2, 3, 130;
    see :data:`RAISE_INTERRUPTS`)."""
    try:
        given = list(sys.argv[1:] if argv is None else argv)
        debug = "--debug" in given
        quiet = "--quiet" in given
        rest = [arg for arg in given if arg not in GLOBAL_FLAGS]
        if not debug:  # Rerun's own log lines repeat errors that headsim reports in one line
            os.environ.setdefault("RUST_LOG", "off")
        from headsim.cli.interrupts import process_signals
        from headsim.errors import guarded

        with process_signals():
            code = guarded(lambda: _main(rest, debug=debug, quiet=quiet), debug=debug)
    except KeyboardInterrupt:  # before the command's own guard, or as it is taken down
        print("headsim: interrupted", file=sys.stderr)
        code = int(ExitCode.INTERRUPTED)
    if argv is not None and code == ExitCode.INTERRUPTED and RAISE_INTERRUPTS:
        raise KeyboardInterrupt  # the command cleaned up; now its caller stops too
    if argv is None and code == ExitCode.INTERRUPTED:
        # CPython ends a process by SIGINT at exit (status -2, not 130) once a
        # KeyboardInterrupt passed through an extension's PyRun_* call (pybind11's exec
        # while mujoco imports), even when it was caught; the next PyRun_* call that
        # succeeds clears that flag, so the process exits with the status returned.
        import ctypes

        ctypes.pythonapi.PyRun_SimpleString(b"pass")
    rerun_cli = sys.modules.get("headsim.runs.rerun_cli")
    if argv is None and rerun_cli is not None and rerun_cli.viewer_streams_left_open():
        # Rerun's gRPC client, left with a viewer that does not answer, blocks the
        # interpreter's exit for ever, signals included: leave without it (all written).
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code
