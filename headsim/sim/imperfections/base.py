"""What an image imperfection is, and the registry that every renderer finishes images with.

An imperfection is one module of :mod:`headsim.sim.imperfections` (or any module that
calls :func:`register`): its camera settings, each declared once as a :class:`Setting`
(type, range, default, unit, meaning: the scenario schema's checks and the scenario-key
reference are made from it), and :meth:`Imperfection.apply`, the one function that puts
it on an image.  The classic renderer, the batch renderer, the window crop and the live
head (through the renderer) finish every image with :func:`finish`, which applies every
registered imperfection in its declared ``order`` without naming any.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np

from headsim.sim.declared import Setting as Setting  # what an imperfection declares with
from headsim.sim.gl_window import Window


class Camera(Protocol):
    """What an imperfection reads of a camera (:class:`headsim.sim.settings.CameraSettings`)."""

    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    def value(self, name: str) -> float: ...


class Canvas(Protocol):
    """The pinhole canvas the renderer draws before any imperfection: its size, px."""

    @property
    def size(self) -> tuple[int, int]: ...


#: An imperfection's source for a window of which nothing needs drawing (black).
NOTHING = Window(0, 0, 0, 0)


@dataclass(frozen=True)
class Shot:
    """One image being finished: its stream ``key`` and number ``frame`` (what seeds its
    noise), the camera's full image size (w, h) px, ``binning`` (a preview binned b x b),
    and, per imperfection, ``window``: the part of the full frame its output is (None:
    all of it) and ``source``: the part of its input image that it gets (None: all)."""

    key: tuple[int, ...]
    frame: int
    full_size: tuple[int, int]
    binning: int = 1
    window: Window | None = None
    source: Window | None = None


class Imperfection:
    """One image imperfection.  Subclasses set ``name``, ``order`` (lower: applied first;
    a lens that resamples the canvas first, pixel effects after) and ``settings``, and
    define :meth:`apply`; :meth:`prepare` and :meth:`source` have identity defaults."""

    name: str = ""
    order: int = 100
    settings: tuple[Setting, ...] = ()

    def prepare(self, camera: Camera, canvas: Canvas) -> Any:
        """What :meth:`apply` needs for ``camera`` (built once per renderer and camera)."""
        return None

    def active(self, state: Any) -> bool:
        """Whether it changes images at all (False: :func:`finish` skips it)."""
        return True

    def source(self, state: Any, window: Window) -> Window:
        """The part of its input that ``window`` of its output needs (:data:`NOTHING`: none)."""
        return window

    def apply(self, image: np.ndarray, state: Any, shot: Shot) -> np.ndarray:
        """``image`` (8-bit RGB; ``shot.source`` of the input) with the imperfection on:
        ``shot.window`` of the output, or the whole image."""
        raise NotImplementedError


_REGISTRY: dict[str, Imperfection] = {}


def register(imperfection: Imperfection) -> Imperfection:
    """Add ``imperfection`` to what every renderer applies (its name must be new, and its
    settings' names new among every registered setting)."""
    if not imperfection.name or imperfection.name in _REGISTRY:
        raise ValueError(f"imperfection name {imperfection.name!r} is empty or taken")
    taken = {s.name for s in all_settings()}
    clash = [s.name for s in imperfection.settings if s.name in taken]
    if clash:
        raise ValueError(f"imperfection {imperfection.name!r}: settings {clash} are taken")
    _REGISTRY[imperfection.name] = imperfection
    return imperfection


def unregister(name: str) -> None:
    """Remove a registered imperfection (tests that add their own)."""
    _REGISTRY.pop(name, None)


def registered() -> tuple[Imperfection, ...]:
    """Every registered imperfection, in the order they are applied."""
    return tuple(sorted(_REGISTRY.values(), key=lambda i: (i.order, i.name)))


def all_settings() -> tuple[Setting, ...]:
    """Every registered imperfection's settings, in the order they are applied."""
    return tuple(s for i in registered() for s in i.settings)


def setting(name: str) -> Setting:
    """The registered setting ``name`` (KeyError: none)."""
    for s in all_settings():
        if s.name == name:
            return s
    raise KeyError(name)


def meanings() -> Mapping[str, str]:
    """Each registered setting's meaning, by name (the scenario-key reference's lines)."""
    return {s.name: s.meaning for s in all_settings()}


#: One camera's imperfections with what each prepared for it, in the order applied.
Stages = tuple[tuple[Imperfection, Any], ...]


def prepare(camera: Camera, canvas: Canvas) -> Stages:
    """Every registered imperfection that changes ``camera``'s images, prepared for it."""
    stages = []
    for imperfection in registered():
        state = imperfection.prepare(camera, canvas)
        if imperfection.active(state):
            stages.append((imperfection, state))
    return tuple(stages)


def finish(
    draw: Callable[[Window | None], np.ndarray],
    stages: Stages,
    shot: Shot,
    window: Window | None = None,
) -> np.ndarray:
    """``window`` of a camera's image (None: all of it), finished: ``draw(rect)`` renders
    ``rect`` of the pinhole canvas (None: all), then each stage applies in order.

    Each stage's output window asks its input for :meth:`Imperfection.source`; a stage
    that needs nothing starts the image black there.
    """
    windows: list[Window | None] = [None] * len(stages)
    sources: list[Window | None] = [None] * len(stages)
    rect, first = window, 0
    image: np.ndarray | None = None
    for index in range(len(stages) - 1, -1, -1):
        imperfection, state = stages[index]
        windows[index] = rect
        if rect is None:
            continue
        source = imperfection.source(state, rect)
        if source == NOTHING:
            image = np.zeros((rect.height, rect.width, 3), dtype=np.uint8)
            first = index + 1
            break
        sources[index] = rect = source
    if image is None:
        image = draw(rect)
    for index in range(first, len(stages)):
        imperfection, state = stages[index]
        image = imperfection.apply(
            image, state, replace(shot, window=windows[index], source=sources[index])
        )
    return image
