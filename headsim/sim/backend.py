"""Choosing and checking the OpenGL backend for off-screen rendering.

MuJoCo reads ``MUJOCO_GL`` once, when it is first imported, and fails on import
for an unknown value or a missing OSMesa.  So headsim decides before anything
imports mujoco:

- ``headsim/__init__.py`` calls :func:`choose_default_backend`: a default when the
  user set none (EGL when libEGL exists, else OSMesa when libOSMesa does), and
  ``MUJOCO_GL=disable`` in place of a value that cannot load, so that ``--help``,
  ``list`` and validation work without GL.  It never raises.
- :func:`check_backend` raises, with one line saying what to install or set, for
  work that renders: ``cli.main`` calls it before any command that renders (exit 3),
  and the renderer before its first image.
"""

from __future__ import annotations

import ctypes
import os

from headsim.errors import EnvironmentProblem

ALLOWED = ("egl", "osmesa", "glfw")
DISABLED = ("disable", "disabled", "off", "false", "0")
INSTALL_HINT = (
    "Off-screen rendering needs EGL (Debian/Ubuntu: apt-get install libegl1 libopengl0 "
    "libgl1-mesa-dri) with MUJOCO_GL=egl, or OSMesa (apt-get install libosmesa6) with "
    "MUJOCO_GL=osmesa."
)
#: The shared libraries each backend loads (via PyOpenGL and MuJoCo), and the package giving them.
LIBRARIES: dict[str, tuple[tuple[str, str], ...]] = {
    "egl": (("EGL", "libegl1"), ("OpenGL", "libopengl0")),
    "osmesa": (("OSMesa", "libosmesa6"),),
    "glfw": (("GL", "libgl1"),),
}


#: The name each library is loaded by where it is installed (glvnd's and Mesa's sonames):
#: loading it answers at once, where a search of the linker's cache starts a subprocess.
SONAMES = {
    "EGL": "libEGL.so.1",
    "OpenGL": "libOpenGL.so.0",
    "OSMesa": "libOSMesa.so.8",
    "GL": "libGL.so.1",
}


def installed(lib: str) -> bool:
    """Whether the shared library ``lib`` (as in ``libEGL``: ``"EGL"``) is there: its usual
    soname loads, or the linker's cache lists it under another."""
    try:
        ctypes.CDLL(SONAMES.get(lib, f"lib{lib}.so"))
        return True
    except OSError:
        from ctypes.util import find_library

        return find_library(lib) is not None


class RenderBackendError(EnvironmentProblem, RuntimeError):
    """No usable OpenGL backend for off-screen rendering (exit 3)."""


#: What :func:`choose_default_backend` found wrong with the user's MUJOCO_GL, if anything.
_problem: str | None = None


def _current() -> str:
    return os.environ.get("MUJOCO_GL", "").strip().lower()


def choose_default_backend() -> str:
    """Set ``MUJOCO_GL`` before mujoco is imported; never raises.

    Unset: EGL when libEGL exists, else OSMesa.  A value that cannot load (unknown,
    or its library missing) is remembered for :func:`check_backend` and replaced by
    ``disable``, so that mujoco still imports for work that does not render.
    """
    global _problem
    current = _current()
    if not current:
        current = "egl"
        if not installed("EGL") and installed("OSMesa"):
            current = "osmesa"
        os.environ["MUJOCO_GL"] = current
    if current not in DISABLED:
        _problem = diagnose()
        if _problem is not None:
            os.environ["MUJOCO_GL"] = "disable"
    return _current()


def diagnose() -> str | None:
    """What is wrong with ``MUJOCO_GL`` for rendering, in one line; None when it can work."""
    name = _current()
    if name in DISABLED:
        return _problem or (
            f"MUJOCO_GL={name} turns rendering off, but this command renders the eye cameras: "
            f"set MUJOCO_GL=egl or MUJOCO_GL=osmesa. {INSTALL_HINT}"
        )
    if name not in ALLOWED:
        return (
            f"MUJOCO_GL={name!r} is not a backend headsim can render with; allowed: "
            f"{', '.join(ALLOWED)}. {INSTALL_HINT}"
        )
    missing = [(lib, pkg) for lib, pkg in LIBRARIES[name] if not installed(lib)]
    if missing:
        libs = " and ".join(f"lib{lib}" for lib, _ in missing)
        pkgs = " ".join(pkg for _, pkg in missing)
        other = "osmesa" if name != "osmesa" else "egl"
        return (
            f"MUJOCO_GL={name} but {libs} is not installed: apt-get install {pkgs} "
            f"(Debian/Ubuntu), or set MUJOCO_GL={other}. {INSTALL_HINT}"
        )
    if name == "glfw" and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return (
            "MUJOCO_GL=glfw needs a display (DISPLAY is not set): use MUJOCO_GL=egl or "
            f"MUJOCO_GL=osmesa for off-screen rendering. {INSTALL_HINT}"
        )
    return None


def check_backend() -> str:
    """Return the active backend name or raise :class:`RenderBackendError` naming the fix."""
    problem = diagnose()
    if problem is not None:
        raise RenderBackendError(problem)
    return _current()
