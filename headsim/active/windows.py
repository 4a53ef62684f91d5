"""Where a servo looks: a window around where the target is expected, a binned
preview to place one, the check that a detection in a window stands for the
full frame's, and each detection reported to the event sink.

A servo knows nothing of the scene but its images: a window where its last sight
puts the target is a guess, which the image in it confirms (the blob found well
inside it, about as large as it was) or not; then the target is looked for
again in a preview (:func:`look_again`), as a target never seen is.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np

from headsim.active.events import Detected
from headsim.active.seen_pattern import SeenPattern, preview_binning
from headsim.active.servo_types import (
    Detector,
    ServoConfig,
)
from headsim.sim.events import EventSink
from headsim.sim.render import Window, unbinned_px
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import Detection
from headsim.vision.markers import find_marker

#: A blob found in a window placed from an earlier sight counts only if its area is
#: within this factor of the area seen then; else the window is a miss.  A target's
#: image area changes little as the eyes or the neck move it across the image (the
#: fast scenarios: within 1.2 but for a 42 px blob crossing the realistic head's
#: distorted image, 1.44), and a lot when it moved in depth, or when the window shows
#: another, smaller blob of its colour (the full frame's answer is the largest one).
AREA_CHANGE = 2.0

#: Detectors (or the functions that partials of them wrap) that find their target
#: in a window: a blob's centroid, decided by the blob and what lies within one blob
#: size of it.  Others (a whole chessboard, a cross point) always see full frames.
WINDOWED_DETECTORS: set[Callable[..., object]] = {find_marker}


def _unwrapped(detector: object) -> object:
    """``detector`` without the ``functools.partial`` layers around it."""
    while isinstance(detector, functools.partial):
        detector = detector.func
    return detector


def windowed(detector: object) -> bool:
    """Whether ``detector`` (possibly a ``functools.partial``) may look at windows."""
    return _unwrapped(detector) in WINDOWED_DETECTORS


#: What :func:`alone_finder` gives: (feature index, ``find_alone(image, spacing_px)``,
#: ``alone_extent_px(spacing_px)`` as (left, top, right, bottom) px from the feature).
AloneFinder = tuple[
    int, Callable[..., Detection], Callable[[float], tuple[float, float, float, float]]
]


def alone_finder(detector: object) -> AloneFinder | None:
    """(feature index, ``find_alone(image, spacing_px)``, ``alone_extent_px(spacing_px)``) of a
    pattern detector that can find its feature alone once the pattern was seen (a
    chessboard's corner), else None."""
    detector = _unwrapped(detector)
    index = getattr(detector, "feature_index", None)
    find = getattr(detector, "find_alone", None)
    extent = getattr(detector, "alone_extent_px", None)
    if index is None or find is None or extent is None:
        return None
    return int(index), find, extent


def pattern_windowed(detector: object) -> bool:
    """Whether ``detector`` finds a feature as part of a pattern it reports the extent of
    (``Detection.extent_px``) and names by a ``window_key`` shared by the pattern's features."""
    return getattr(_unwrapped(detector), "window_key", None) is not None


def reporting(
    detector: Detector, sink: EventSink, camera: int, window: Window | None = None
) -> Detector:
    """``detector``, reporting to ``sink`` each detection it makes in camera ``camera``'s
    image (:class:`headsim.active.events.Detected`; in a ``window``, its offset added)."""

    def detect(image: np.ndarray) -> Detection:
        detection = detector(image)
        uv = detection.uv if detection.found else None
        if uv is not None and window is not None:  # in the full frame's pixels
            uv = (uv[0] + window.x0, uv[1] + window.y0)
        sink.emit(Detected(camera, detection.status, uv))
        return detection

    return detect


def pattern_window(
    sim: HeadSim,
    camera: int,
    expected_uv: tuple[float, float],
    extent_px: tuple[float, float, float, float],
    motion_px: float,
    margin_px: float,
) -> Window | None:
    """The window to look for a pattern of ``extent_px`` around ``expected_uv`` after an
    image motion of ``motion_px``: the extent plus the margin and a quarter of the motion
    on every side.  None where it would be barely cheaper than the frame."""
    settings = sim.camera_settings(camera)
    grow = margin_px + 0.25 * abs(motion_px)
    u, v = expected_uv
    left, top, right, bottom = extent_px
    x0 = max(math.floor(u + left - grow), 0)
    y0 = max(math.floor(v + top - grow), 0)
    x1 = min(math.ceil(u + right + grow) + 1, settings.width)
    y1 = min(math.ceil(v + bottom + grow) + 1, settings.height)
    if x1 <= x0 or y1 <= y0 or (x1 - x0) * (y1 - y0) >= 0.5 * settings.width * settings.height:
        return None
    return Window(int(x0), int(y0), int(x1 - x0), int(y1 - y0))


def expected_window(
    sim: HeadSim,
    camera: int,
    expected_uv: tuple[float, float],
    area_px: float,
    motion_px: float,
    margin_px: float,
) -> Window | None:
    """The window to look for a blob of ``area_px`` expected at ``expected_uv`` after an
    image motion of ``motion_px``: half-side 3 blob radii + margin + a quarter of the
    motion.  None where it would be barely cheaper than the frame."""
    half = 3.0 * math.sqrt(area_px / math.pi) + margin_px + 0.25 * abs(motion_px)
    settings = sim.camera_settings(camera)
    window = Window.around(expected_uv, half, (settings.width, settings.height))
    if window.width * window.height >= 0.5 * settings.width * settings.height:
        return None
    return window


def preview_window(
    sim: HeadSim, camera: int, detector: object, config: ServoConfig, binning: int = 0
) -> Window | None:
    """Render a preview of ``camera``'s whole view binned b x b (``binning``, default
    ``config.preview_binning``) and return the window where it shows the target (a
    blob's, or a whole pattern's box), or None (not found, or a window barely cheaper
    than the frame: a full frame follows)."""
    b = binning or config.preview_binning
    assert callable(detector)
    seen = detector(sim.render_preview(camera, b))
    if not isinstance(seen, Detection) or not seen.found or seen.uv is None:
        return None
    # Its position is good to about b px.
    u, v = unbinned_px(seen.uv, b)
    uv = (float(u), float(v))
    if seen.extent_px is not None:  # a pattern: its box, from the feature
        left, top, right, bottom = (b * e for e in seen.extent_px)
        return pattern_window(
            sim, camera, uv, (left, top, right, bottom), 4.0 * b, config.window_margin_px
        )
    return expected_window(sim, camera, uv, b * b * seen.area_px, 4.0 * b, config.window_margin_px)


def look_again(
    sim: HeadSim,
    camera: int,
    detector: object,
    config: ServoConfig,
    report: Callable[[Window], Detector],
) -> tuple[Detection | None, bool]:
    """After a window placed from an earlier sight missed (the target moved, or the window
    shows something else): ``detector``'s blob found again in a binned preview, and
    detected (by ``report(window)``) in the window the preview places, retaken of the
    same instant.  Returns the detection (None: not in the preview, or that window
    missed too: the full frame follows) and whether that window was rendered."""
    window = preview_window(sim, camera, detector, config)
    if window is None:
        return None, False
    return look_in_window(sim, camera, report(window), window, retake=True), True


def look_once(
    sim: HeadSim,
    camera: int,
    detector: Detector,
    config: ServoConfig | None = None,
    binning: int = 0,
) -> Detection:
    """``detector``'s answer on ``camera``'s next image, from as few pixels as the full
    frame's answer needs: the window a binned preview places (:func:`preview_window`),
    where the detection counts if it stands for the full frame's (:func:`look_in_window`),
    else the full frame of the same instant.  For a camera that looks once at a target
    it has no sight of yet (stereo, chessboard views); a servo predicts its windows."""
    config = config or ServoConfig()
    if config.windows and (binning or config.preview_binning) > 1:
        window = preview_window(sim, camera, detector, config, binning)
        if window is not None:
            seen = look_in_window(sim, camera, detector, window)
            return seen if seen is not None else detector(sim.retake(camera))
    return detector(sim.render(camera))


def pattern_preview(
    sim: HeadSim,
    camera: int,
    detector: object,
    kept: SeenPattern,
    alone: AloneFinder,
    config: ServoConfig,
) -> tuple[SeenPattern | None, Window | None] | None:
    """After a move too long to find a feature alone, the pattern (``detector``'s, last
    seen as ``kept``) found in a binned preview of ``camera``'s whole view, and the
    window to look for feature ``alone[0]`` alone there.  None: no binning keeps the
    pattern findable (nothing rendered); (None, None): the preview did not show it."""
    settings = sim.camera_settings(camera)
    b = preview_binning(kept.spacing_px, config.preview_binning, (settings.width, settings.height))
    if b <= 1:
        return None
    assert callable(detector)
    seen = SeenPattern.from_preview(detector(sim.render_preview(camera, b)), b)
    if seen is None:
        return None, None
    index, _, extent = alone
    u, v = seen.features[index]
    # The preview places each feature to within about b px.
    window = pattern_window(
        sim, camera, (u, v), extent(seen.spacing_px), 4.0 * b, config.window_margin_px
    )
    return seen, window


def look_in_window(
    sim: HeadSim,
    camera: int,
    detector: Detector,
    window: Window,
    expected_area_px: float | None = None,
    retake: bool = False,
) -> Detection | None:
    """Render ``window`` and detect there: the detection in full-frame pixels, or None (a miss).

    It counts only if FOUND at least 3 blob radii + 2 px inside the window, so
    that the blob and every piece the detector looks for beside it (within one
    blob size) lie in the window: then the full frame gives the same answer.
    ``expected_area_px``: the blob's area where an earlier sight placed the window;
    a blob whose area is not within :data:`AREA_CHANGE` of it is a miss too.
    ``retake``: the window is of the instant just taken (``HeadSim.render_window``).
    """
    seen = detector(sim.render_window(camera, window, retake=retake))
    if not seen.found or seen.uv is None:
        return None
    if expected_area_px is not None and not (
        expected_area_px / AREA_CHANGE <= seen.area_px <= AREA_CHANGE * expected_area_px
    ):
        return None
    u, v = seen.uv[0] + window.x0, seen.uv[1] + window.y0
    if seen.extent_px is not None:
        # A pattern counts only if all of it lies 2 px inside the window, or runs
        # off a side where the window's edge is the image's (the full frame ends there too).
        left, top, right, bottom = seen.extent_px
        settings = sim.camera_settings(camera)
        if (
            (window.x0 == 0 or window.x0 + 2 <= u + left)
            and (window.x1 == settings.width or u + right <= window.x1 - 3)
            and (window.y0 == 0 or window.y0 + 2 <= v + top)
            and (window.y1 == settings.height or v + bottom <= window.y1 - 3)
        ):
            return seen.moved(window.x0, window.y0)
        return None
    inset = 3.0 * math.sqrt(seen.area_px / math.pi) + 2.0
    if (
        window.x0 + inset <= u <= window.x1 - 1 - inset
        and window.y0 + inset <= v <= window.y1 - 1 - inset
    ):
        return seen.moved(window.x0, window.y0)
    return None


__all__ = [
    "AREA_CHANGE",
    "WINDOWED_DETECTORS",
    "AloneFinder",
    "alone_finder",
    "expected_window",
    "look_again",
    "look_in_window",
    "look_once",
    "pattern_preview",
    "pattern_window",
    "pattern_windowed",
    "preview_window",
    "reporting",
    "windowed",
]
