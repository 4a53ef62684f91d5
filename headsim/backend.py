"""Choosing and checking the OpenGL backend for off-screen rendering.

MuJoCo reads ``MUJOCO_GL`` once, when it is first imported, so headsim sets a
default (EGL, else OSMesa) in ``headsim/__init__.py`` before anything imports
mujoco.  Failures become a :class:`RenderBackendError` that says what to
install or set.
"""

from __future__ import annotations

import ctypes.util
import os

ALLOWED = ("egl", "osmesa", "glfw")
DISABLED = ("disable", "disabled", "off", "false", "0")
INSTALL_HINT = (
    "Off-screen rendering needs EGL (Debian/Ubuntu: apt-get install libegl1 libgl1-mesa-dri) "
    "with MUJOCO_GL=egl, or OSMesa (apt-get install libosmesa6) with MUJOCO_GL=osmesa. "
    "Set MUJOCO_GL before Python imports mujoco."
)


class RenderBackendError(RuntimeError):
    """No usable OpenGL backend for off-screen rendering."""


def choose_default_backend() -> str:
    """Set ``MUJOCO_GL`` if the user did not: EGL when libEGL exists, else OSMesa."""
    current = os.environ.get("MUJOCO_GL", "").strip().lower()
    if current:
        if current not in ALLOWED + DISABLED:
            raise RenderBackendError(
                f"MUJOCO_GL={current!r} is not a backend headsim can render with; allowed: "
                f"{', '.join(ALLOWED)} (or 'disable' for no rendering). {INSTALL_HINT}"
            )
        return current
    chosen = "egl"
    if ctypes.util.find_library("EGL") is None and ctypes.util.find_library("OSMesa") is not None:
        chosen = "osmesa"
    os.environ["MUJOCO_GL"] = chosen
    return chosen


def check_backend() -> str:
    """Return the active backend name or raise :class:`RenderBackendError` naming the fix."""
    name = os.environ.get("MUJOCO_GL", "").strip().lower()
    if name not in ALLOWED:
        raise RenderBackendError(
            f"MUJOCO_GL={name!r} is not a backend headsim can render with; allowed: "
            f"{', '.join(ALLOWED)}. {INSTALL_HINT}"
        )
    library = {"egl": "EGL", "osmesa": "OSMesa", "glfw": "glfw"}[name]
    if name != "glfw" and ctypes.util.find_library(library) is None:
        raise RenderBackendError(
            f"MUJOCO_GL={name} but lib{library} is not installed. {INSTALL_HINT}"
        )
    return name
