"""The one adapter to :class:`mujoco.Renderer`'s private state.

headsim draws windows and previews itself (``mjr_render`` into its own
viewports and framebuffers), which needs what the public ``Renderer`` keeps
private: its model, its ``MjrContext`` and its OpenGL context.  Every such
access goes through this module, so that a MuJoCo release that moves one
fails here, by name (:func:`check_renderer`), and nowhere else.
"""

from __future__ import annotations

import mujoco

#: The private attributes of ``mujoco.Renderer`` headsim reads or sets.
PRIVATE_ATTRIBUTES = ("_model", "_mjr_context", "_gl_context")


class RendererInternalsError(RuntimeError):
    """A private attribute of ``mujoco.Renderer`` headsim relies on is missing."""


def check_renderer(renderer: object) -> None:
    """Raise :class:`RendererInternalsError` naming the first private attribute
    of :data:`PRIVATE_ATTRIBUTES` that ``renderer`` lacks, and MuJoCo's version."""
    for name in PRIVATE_ATTRIBUTES:
        if not hasattr(renderer, name):
            raise RendererInternalsError(
                f"mujoco.Renderer has no attribute {name!r} in MuJoCo {mujoco.__version__}: "
                "headsim.sim.mujoco_renderer must be adapted to this release"
            )


def use_model(renderer: mujoco.Renderer, model: mujoco.MjModel) -> None:
    """Make ``renderer`` read cameras and bodies from ``model`` (same uploaded assets)."""
    renderer._model = model


def mjr_context(renderer: mujoco.Renderer) -> mujoco.MjrContext:
    """The renderer's ``MjrContext``."""
    context: mujoco.MjrContext = renderer._mjr_context
    return context


def make_current(renderer: mujoco.Renderer) -> None:
    """Make the renderer's OpenGL context current (where it has one of its own)."""
    gl_context = renderer._gl_context
    if gl_context is not None:
        gl_context.make_current()


__all__ = [
    "PRIVATE_ATTRIBUTES",
    "RendererInternalsError",
    "check_renderer",
    "make_current",
    "mjr_context",
    "use_model",
]
