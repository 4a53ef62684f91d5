"""Where a run's events go, and the one event the simulator itself reports: an image taken.

An :class:`EventSink` receives events as they happen (``emit``); the simulator,
the servos and the procedures report to the sink they are given, and a run's
subscribers (progress, recording, the runner's counts) read them.  Events are
frozen dataclasses; the procedures' and servos' own are in
:mod:`headsim.active.events`.  Reporting never changes what is measured: a sink
only reads.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from headsim.codec import declared, doc
from headsim.sim.render import Window


class EventSink(Protocol):
    """Anything that takes a run's events, one call each, in the order they happen."""

    def emit(self, event: object) -> None: ...


class NoEvents:
    """The sink that drops every event (the default: nothing subscribes)."""

    def emit(self, event: object) -> None:
        """Drop ``event``."""


#: The shared do-nothing sink.
NO_EVENTS = NoEvents()


class ImageKind(enum.Enum):
    """How an image was taken (each one is counted as a render by the simulator)."""

    FULL = "full"  # the camera's whole image
    # the instant a window was just taken of (it missed) taken again: the whole image, or
    # the window a preview placed (``ImageTaken.window``)
    RETAKE = "retake"
    WINDOW = "window"  # only a window of the image (``ImageTaken.window``)
    PREVIEW = "preview"  # the whole view binned ``binning`` x ``binning``, to place a window


@declared
class RenderCounts:
    """Images the simulator drew, by kind; every one of them is a render (``total``), the
    way ``HeadSim.render_count`` counts them (results.json's meanings below).

    ``images``: whole frames (FULL); ``windows``: windows (WINDOW); ``retakes``: the
    instant of a window that missed taken again, whole or as the window a preview
    placed (RETAKE); ``previews``: binned previews (PREVIEW).
    """

    images: int = doc("full frames", default=0)
    windows: int = doc("windows", default=0)
    retakes: int = doc("windows retaken whole at the same instant", default=0)
    previews: int = doc("binned previews", default=0)
    total: int = doc(
        "all of them (full frames, windows, retakes and previews)", init=False, compare=False
    )

    def __post_init__(self) -> None:
        object.__setattr__(self, "total", sum(self._kinds()))

    def _kinds(self) -> tuple[int, int, int, int]:
        return (self.images, self.windows, self.retakes, self.previews)

    def counted(self, kind: ImageKind) -> RenderCounts:
        """These counts and one image of ``kind``."""
        field = _COUNTED[kind]
        return replace(self, **{field: getattr(self, field) + 1})

    def __add__(self, other: RenderCounts) -> RenderCounts:
        return RenderCounts(*(a + b for a, b in zip(self._kinds(), other._kinds(), strict=True)))

    def __sub__(self, other: RenderCounts) -> RenderCounts:
        return RenderCounts(*(a - b for a, b in zip(self._kinds(), other._kinds(), strict=True)))


#: The field of :class:`RenderCounts` that counts each kind of image.
_COUNTED = {
    ImageKind.FULL: "images",
    ImageKind.WINDOW: "windows",
    ImageKind.RETAKE: "retakes",
    ImageKind.PREVIEW: "previews",
}


@dataclass(frozen=True)
class ImageTaken:
    """Camera 1 or 2 took ``image`` (H, W, 3) uint8 as rendered: the whole image, the
    window's crop, or the binned preview.

    ``window``: where a WINDOW image (or a RETAKE of a window) lies in the full frame,
    px (None: the whole image);
    ``binning``: a PREVIEW's binning (1 otherwise); ``rendered_frames``: the pixels
    this image cost, in full frames (the simulator's ``rendered_frames`` increment).
    """

    camera: int
    image: np.ndarray
    kind: ImageKind
    rendered_frames: float
    window: Window | None = None
    binning: int = 1


__all__ = ["NO_EVENTS", "EventSink", "ImageKind", "ImageTaken", "NoEvents", "RenderCounts"]
