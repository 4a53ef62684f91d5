"""The ``headsim`` command line: ``run`` a scenario, ``list`` them, take a ``snapshot``, ...

Exit status (the contract of :mod:`headsim.errors`, held by every command): 0
everything succeeded; 1 a measurement or job failed; 2 bad input or arguments,
found before anything runs; 3 the environment (no GL backend, output not
writable, disk full, a dependency missing); 130 interrupted.  No traceback
reaches the user; ``--debug`` shows one.

This package imports only the standard library (and :mod:`headsim.errors`,
:mod:`headsim.run.outputs`, :mod:`headsim.sim.backend`) at the top of its modules, so
that ``--help``, ``list`` and an interrupt during start-up are handled before numpy or
mujoco load.  The entry point is here (``headsim.cli:main``); one module per command
group: :mod:`~headsim.cli.scenarios` (run, calibrate, list), :mod:`~headsim.cli.studies`
(reproduce, study, bench, sweep), :mod:`~headsim.cli.snapshot`; the arguments in
:mod:`~headsim.cli.parser`.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Sequence

from headsim.cli.interrupts import process_signals
from headsim.cli.parser import build_parser
from headsim.errors import ExitCode, guarded
from headsim.sim import backend

#: Commands that never render: they run without any GL backend (so does ``--help``).
RENDER_FREE_COMMANDS = frozenset({"list"})
#: Options every command takes, anywhere on the command line.
GLOBAL_FLAGS = ("--debug", "--quiet")


def _command(argv: Sequence[str]) -> str | None:
    """The subcommand named on the command line (None for ``--help`` or none)."""
    if any(arg in ("-h", "--help") for arg in argv):
        return None
    return next((arg for arg in argv if not arg.startswith("-")), None)


def _main(argv: list[str], *, debug: bool, quiet: bool) -> int:
    command = _command(argv)
    if command is not None and command not in RENDER_FREE_COMMANDS:
        backend.check_backend()  # MUJOCO_GL was settled when headsim was imported
    args = build_parser(with_study="study" in argv).parse_args(argv)
    args.debug, args.quiet = debug, quiet
    return int(args.func(args))


def main(argv: Sequence[str] | None = None) -> int:
    """The ``headsim`` entry point: runs a command and returns its exit code (0, 1, 2, 3, 130)."""
    given = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in given
    quiet = "--quiet" in given
    rest = [arg for arg in given if arg not in GLOBAL_FLAGS]
    if not debug:  # Rerun's own log lines repeat errors that headsim reports in one line
        os.environ.setdefault("RUST_LOG", "off")
    with process_signals():
        code = guarded(lambda: _main(rest, debug=debug, quiet=quiet), debug=debug)
    if argv is None and (code == ExitCode.INTERRUPTED or _nothing_left_running()):
        # The process's own entry point, its command done: every file it wrote is closed
        # (results written atomically, a recording flushed and disconnected).  Leave now:
        # tearing the interpreter down frees mujoco's, llvmpipe's and Rerun's state for
        # about 0.3 s (a tenth of the quick start).  Interrupted, leave in any case, for
        # CPython ends a process by SIGINT at exit (status -2, not 130) once a
        # KeyboardInterrupt passed through an extension's PyRun_* call (pybind11's exec
        # while mujoco imports), even when headsim caught it.
        with contextlib.suppress(OSError):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(int(code))
    return code


def _nothing_left_running() -> bool:
    """Whether no thread but daemons is left and no process was started (else the
    interpreter's own exit waits for them, and multiprocessing's finalizers hand its
    semaphores back: without them its resource tracker warns of leaked ones)."""
    others = [t for t in threading.enumerate() if t is not threading.main_thread()]
    if any(t.is_alive() and not t.daemon for t in others):
        return False
    return "multiprocessing" not in sys.modules
