"""headsim: a MuJoCo testbed for vergence-based active stereo vision on humanoid heads."""

import os as _os
import signal as _signal
import sys as _sys


def _interrupted_during_start_up(signum: int, frame: object) -> None:
    """Ctrl-C before the CLI installs its handlers: exit 130 at once, no traceback."""
    _os.write(2, b"headsim: interrupted during start-up; nothing written\n")
    _os._exit(130)


# Run as the ``headsim`` command, an interrupt while the CLI loads must not end in Python's
# KeyboardInterrupt traceback (``headsim.cli.main`` replaces this handler); a library
# import leaves SIGINT alone.
_COMMAND = _os.path.basename(_sys.argv[0]) == "headsim" or _sys.orig_argv[1:3] in (
    ["-m", "headsim"],
    ["-m", "headsim.cli"],
)
if _COMMAND and _signal.getsignal(_signal.SIGINT) is _signal.default_int_handler:
    _signal.signal(_signal.SIGINT, _interrupted_during_start_up)

from headsim.sim.backend import choose_default_backend  # noqa: E402

# MuJoCo picks its OpenGL backend when first imported: choose before that.
choose_default_backend()

__version__ = "0.1.0"
