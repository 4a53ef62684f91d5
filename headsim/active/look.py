"""One way to look: a servo asks for a detection, and this module decides which image
to render for it (a whole frame, a window, a binned preview) and keeps what it needs
between looks.

A servo knows nothing of the scene but its images.  A window placed where its last
sight puts the target is a guess, which the image in it confirms (the blob found well
inside it, about as large as it was; a pattern wholly inside it) or not; a miss is
looked for again in a preview, then in the same instant's full frame.  Never from the
truth, nor from whether the scene changed: detections, gains, encoders.

The servos call :meth:`Looker.look` with a :data:`Hint`; nothing else here renders.
What a detector can do is declared by the protocols :class:`BlobDetector`,
:class:`PatternFeature` and :class:`FovealDetector`; a detector that declares none
always sees whole frames.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from functools import partial
from typing import Protocol, runtime_checkable

import numpy as np

from headsim.active.events import Detected
from headsim.active.servo_types import Detector, ServoConfig
from headsim.head.servo_head import ServoHead
from headsim.sim.events import EventSink
from headsim.sim.render import Window
from headsim.vision.detection import Detection

#: A blob found in a window placed from an earlier sight counts only if its area is
#: within this factor of the area seen then; else the window is a miss.  A target's
#: image area changes little as the eyes or the neck move it across the image (the
#: fast scenarios: within 1.2 but for a 42 px blob crossing the realistic head's
#: distorted image, 1.44), and a lot when it moved in depth, or when the window shows
#: another, smaller blob of its colour (the full frame's answer is the largest one).
AREA_CHANGE = 2.0

Extent = tuple[float, float, float, float]


# -- what a detector can do --------------------------------------------------------
@runtime_checkable
class BlobDetector(Protocol):
    """A detector of a blob (a centroid and an area) whose answer is decided by the blob
    and what lies within one blob size of it: a window around the blob gives the full
    frame's answer, and a binned preview finds it."""

    @property
    def finds_blob(self) -> bool: ...

    def __call__(self, image: np.ndarray) -> Detection: ...


@runtime_checkable
class PatternFeature(Protocol):
    """A detector of one feature of a pattern (a chessboard's corner) that reports the
    pattern's extent (``Detection.extent_px``): the pattern's features share their
    windows, which hold the whole pattern."""

    @property
    def window_key(self) -> Hashable:
        """What the pattern's features share: their windows and the last sight."""
        ...

    def __call__(self, image: np.ndarray) -> Detection: ...


@runtime_checkable
class FovealDetector(Protocol):
    """A detector that correlates a template on a foveal window
    (:mod:`headsim.active.markerless`): it names the window it needs in ``camera``'s
    image of ``image_size_px`` (width, height), around where the looker expects its
    point (``expected_uv_px``, full-frame pixels, after an image motion of
    ``motion_px``; None: around its own last sight), and is told where the image it is
    handed lies in the full frame; its detection is in full-frame pixels.  Only that
    window is rendered."""

    def search_window(
        self,
        camera: int,
        image_size_px: tuple[int, int],
        expected_uv_px: tuple[float, float] | None,
        motion_px: float = 0.0,
    ) -> Window: ...

    def locate(self, camera: int, image: np.ndarray, origin_px: tuple[int, int]) -> Detection: ...

    def __call__(self, image: np.ndarray) -> Detection: ...


def foveal_detector(detector: object) -> FovealDetector | None:
    """``detector`` as a :class:`FovealDetector`, or None where it is not one."""
    return detector if isinstance(detector, FovealDetector) else None


def finds_blob(detector: object) -> bool:
    """Whether ``detector`` declares itself a :class:`BlobDetector`."""
    return isinstance(detector, BlobDetector) and detector.finds_blob


def pattern_feature(detector: object) -> PatternFeature | None:
    """``detector`` as a :class:`PatternFeature`, or None where it is not one."""
    return detector if isinstance(detector, PatternFeature) else None


# -- what the caller tells of its target ---------------------------------------------
@dataclass(frozen=True)
class Since:
    """The eye servo's hint: the look's own last sight of the target, moved by
    ``gain_px_per_step`` times the eye steps since (None: no gain learnt yet).
    ``preview``: False for a search's look (a whole frame where nothing is predicted)."""

    gain_px_per_step: float | None
    preview: bool = True
    key: object = None


@dataclass(frozen=True)
class Around:
    """The neck servo's hint: its own prediction of the blob ``key`` found: at
    ``uv_px`` (full-frame pixels), of ``area_px`` (px^2), after an image motion of
    ``motion_px``."""

    key: object
    uv_px: tuple[float, float]
    area_px: float
    motion_px: float


@dataclass(frozen=True)
class Anew:
    """A target the caller has no sight of yet (found first in a binned preview)."""

    key: object
    binning: int = 0


@dataclass(frozen=True)
class Whole:
    """The whole frame, nothing else."""


@dataclass(frozen=True)
class Glance:
    """Only the whole view binned ``binning`` x ``binning`` (a scan's look): the
    detection is in the preview's pixels and is not reported."""

    binning: int


Hint = Since | Around | Anew | Whole | Glance


# -- what is kept between looks ------------------------------------------------------
@dataclass(frozen=True)
class Sight:
    """A camera's last detection the next window is predicted from: what the head saw
    (``key``'s target at ``uv_px``, full-frame pixels, of ``area_px``, px^2) and where
    its encoders stood (the eye motor's ``eye_steps``, the neck's (yaw, pitch) ``neck_rad``)."""

    key: object
    eye_steps: int
    neck_rad: tuple[float, float]
    uv_px: tuple[float, float]
    area_px: float


def unbinned_px(binned_px: tuple[float, ...] | np.ndarray, binning: int) -> np.ndarray:
    """Full-frame pixel coordinates of coordinates in a preview binned ``binning`` x
    ``binning`` (``ServoHead.render_preview``): binned pixel i covers pixels
    b i .. b i + b - 1, so its centre is b i + (b - 1) / 2."""
    return binning * np.asarray(binned_px, dtype=np.float64) + (binning - 1) / 2.0


# -- where a window goes (pure) ------------------------------------------------------
def pattern_window(
    image_size_px: tuple[int, int],
    expected_uv_px: tuple[float, float],
    extent_px: Extent,
    motion_px: float,
    margin_px: float,
) -> Window | None:
    """The window to look for a pattern of ``extent_px`` around ``expected_uv_px`` (full
    frame) after an image motion of ``motion_px``: the extent plus the margin and a
    quarter of the motion on every side.  None where it would be barely cheaper than the
    frame."""
    width, height = image_size_px
    grow = margin_px + 0.25 * abs(motion_px)
    u, v = expected_uv_px
    left, top, right, bottom = extent_px
    x0 = max(math.floor(u + left - grow), 0)
    y0 = max(math.floor(v + top - grow), 0)
    x1 = min(math.ceil(u + right + grow) + 1, width)
    y1 = min(math.ceil(v + bottom + grow) + 1, height)
    if x1 <= x0 or y1 <= y0 or (x1 - x0) * (y1 - y0) >= 0.5 * width * height:
        return None
    return Window(int(x0), int(y0), int(x1 - x0), int(y1 - y0))


def expected_window(
    image_size_px: tuple[int, int],
    expected_uv_px: tuple[float, float],
    area_px: float,
    motion_px: float,
    margin_px: float,
) -> Window | None:
    """The window to look for a blob of ``area_px`` expected at ``expected_uv_px`` (full
    frame) after an image motion of ``motion_px``: half-side 3 blob radii + margin + a
    quarter of the motion.  None where it would be barely cheaper than the frame."""
    half = 3.0 * math.sqrt(area_px / math.pi) + margin_px + 0.25 * abs(motion_px)
    window = Window.around(expected_uv_px, half, image_size_px)
    if window.width * window.height >= 0.5 * image_size_px[0] * image_size_px[1]:
        return None
    return window


#: A band's rows reach this fraction of the image width above and below the blob's
#: last sight (besides 3 blob radii and the margin): how far a blob may drift across
#: the rows while an eye's yaw of unknown image motion carries it along them (the
#: lens bends its path).  A blob outside the band is a miss, looked for again.
BAND_DRIFT = 0.05


def band_window(
    image_size_px: tuple[int, int],
    seen_uv_px: tuple[float, float],
    area_px: float,
    margin_px: float,
) -> Window | None:
    """The window to look for a blob of ``area_px`` last seen at ``seen_uv_px`` after an
    eye move of unknown image motion (no gain learnt yet): every column of the rows
    within 3 blob radii + margin + :data:`BAND_DRIFT` of the width of the sight's row.
    None where it would be barely cheaper than the frame."""
    width, height = image_size_px
    half = 3.0 * math.sqrt(area_px / math.pi) + margin_px + BAND_DRIFT * width
    side = min(height, 2 * math.ceil(half) + 1)
    if side >= 0.5 * height:
        return None
    y0 = min(max(round(seen_uv_px[1] - side / 2), 0), height - side)
    return Window(0, int(y0), int(width), int(side))


def stands_for_frame(
    seen: Detection,
    window: Window,
    image_size_px: tuple[int, int],
    expected_area_px: float | None = None,
) -> Detection | None:
    """``seen`` (detected in ``window``) in full-frame pixels if the full frame would give
    the same answer, else None (a miss).

    A blob counts only if FOUND at least 3 blob radii + 2 px inside the window, so that
    the blob and every piece the detector looks for beside it (within one blob size) lie
    in the window; with ``expected_area_px`` (an earlier sight placed the window), only
    if its area is within :data:`AREA_CHANGE` of it.  A pattern counts only if all of it
    lies 2 px inside the window, or runs off a side where the window's edge is the
    image's (the full frame ends there too).
    """
    if not seen.found or seen.uv is None:
        return None
    if expected_area_px is not None and not (
        expected_area_px / AREA_CHANGE <= seen.area_px <= AREA_CHANGE * expected_area_px
    ):
        return None
    u, v = seen.uv[0] + window.x0, seen.uv[1] + window.y0  # in the full frame
    width, height = image_size_px
    if seen.extent_px is not None:
        left, top, right, bottom = seen.extent_px
        if (
            (window.x0 == 0 or window.x0 + 2 <= u + left)
            and (window.x1 == width or u + right <= window.x1 - 3)
            and (window.y0 == 0 or window.y0 + 2 <= v + top)
            and (window.y1 == height or v + bottom <= window.y1 - 3)
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


def reporting(
    detector: Detector, sink: EventSink, camera: int, window: Window | None = None
) -> Detector:
    """``detector``, reporting to ``sink`` each detection it makes in camera ``camera``'s
    image (:class:`headsim.active.events.Detected`; in a ``window``, its offset added)."""

    def detect(image: np.ndarray) -> Detection:
        detection = detector(image)
        uv_px = detection.uv if detection.found else None
        if uv_px is not None and window is not None:  # in the full frame's pixels
            uv_px = (uv_px[0] + window.x0, uv_px[1] + window.y0)
        sink.emit(Detected(camera, detection.status, uv_px))
        return detection

    return detect


def look_once(
    sim: ServoHead,
    camera: int,
    detector: Detector,
    config: ServoConfig | None = None,
    binning: int = 0,
) -> Detection:
    """``detector``'s answer on ``camera``'s next image, for a caller that looks once at a
    target it has no sight of yet and keeps nothing (stereo, chessboard views):
    :meth:`Looker.look` with :class:`Anew`, unreported."""
    return Looker(sim, config, report=False).look(camera, detector, Anew(detector, binning))


# -- the look ------------------------------------------------------------------------
@dataclass
class LookCounts:
    """Binned previews rendered to place a window, windows rendered, and windows that
    missed the target (a full frame, or a preview's window, followed)."""

    previews: int = 0
    window_renders: int = 0
    window_misses: int = 0


@dataclass
class _Memory:
    """Per camera: the last sight, and the extent of the pattern last seen (None: a blob)."""

    sight: dict[int, Sight] = field(default_factory=dict)
    extent_px: dict[int, Extent | None] = field(default_factory=dict)


class Looker:
    """A servo's eyes on the simulator: :meth:`look` renders what a :data:`Hint` calls for
    and detects there, and keeps what the next look is predicted from."""

    def __init__(
        self,
        sim: ServoHead,
        config: ServoConfig | None = None,
        sink: EventSink | None = None,
        report: bool = True,
    ) -> None:
        self.sim = sim
        self.config = config or ServoConfig()
        self.sink = sim.sink if sink is None else sink
        self._report = report
        self.counts = LookCounts()
        self._memory = _Memory()
        #: Each camera's image size (width, height) px, by camera (1, 2).
        self.image_sizes_px = {
            n: (camera.width, camera.height) for n, camera in enumerate(sim.settings.cameras, 1)
        }

    def look(self, camera: int, detector: Detector, hint: Hint) -> Detection:
        """``detector``'s answer on ``camera``'s next image, from as few pixels as the full
        frame's answer needs (see each :data:`Hint`)."""
        foveal = foveal_detector(detector)
        if foveal is not None and not isinstance(hint, Glance):
            return self._foveal(camera, foveal, hint)
        if isinstance(hint, Since):
            return self._since(camera, detector, hint)
        if isinstance(hint, Glance):
            return detector(self._take(camera, binning=hint.binning))
        cfg = self.config
        if isinstance(hint, Around) and cfg.windows and finds_blob(hint.key):
            window = expected_window(
                self.image_sizes_px[camera], hint.uv_px, hint.area_px, hint.motion_px,
                cfg.window_margin_px,
            )  # fmt: skip
            if window is not None:
                return self._confirm(camera, detector, hint.key, window, hint.area_px)
        elif isinstance(hint, Anew) and self._previews(hint):
            self.counts.previews += 1
            window = self._preview_window(camera, hint.key, hint.binning)
            if window is not None:
                return self._confirm(camera, detector, hint.key, window)
        return self._reported(detector, camera)(self._take(camera))

    def _previews(self, hint: Anew) -> bool:
        """Whether a new target is looked for in a preview first."""
        if not self.config.windows or (hint.binning or self.config.preview_binning) <= 1:
            return False
        # One-time looks (no key of a servo's) place any detector's window from a preview.
        return not self._report or finds_blob(hint.key)

    def _reported(self, detector: Detector, camera: int, window: Window | None = None) -> Detector:
        return reporting(detector, self.sink, camera, window) if self._report else detector

    def _confirm(
        self,
        camera: int,
        detector: Detector,
        key: object,
        window: Window,
        guessed_area_px: float | None = None,
    ) -> Detection:
        """Detect in a rendered window; a miss costs the same instant's whole frame, or,
        for a window guessed from a blob of ``guessed_area_px`` seen before, first a
        preview and the window it places."""
        self.counts.window_renders += 1
        detection = self._in_window(
            camera, self._reported(detector, camera, window), window, guessed_area_px
        )
        if detection is not None:
            return detection
        self.counts.window_misses += 1
        if guessed_area_px is not None and self.config.preview_binning > 1:
            self.counts.previews += 1
            report = partial(reporting, detector, self.sink, camera)
            detection, rendered = self._look_again(camera, key, report)
            self.counts.window_renders += rendered
            if detection is not None:
                return detection
            self.counts.window_misses += rendered
        return self._reported(detector, camera)(self._take(camera, retake=True))

    # -- images ------------------------------------------------------------------------
    def _take(
        self, camera: int, window: Window | None = None, binning: int = 1, retake: bool = False
    ) -> np.ndarray:
        """The one place a look renders: ``camera``'s whole frame, a ``window`` of it, or
        its whole view binned ``binning`` x ``binning``; ``retake``: of the instant just
        taken (the same noise)."""
        if binning > 1:
            return self.sim.render_preview(camera, binning)
        if window is not None:
            return self.sim.render_window(camera, window, retake=retake)
        return self.sim.retake(camera) if retake else self.sim.render(camera)

    def _in_window(
        self,
        camera: int,
        detector: Detector,
        window: Window,
        expected_area_px: float | None = None,
        retake: bool = False,
    ) -> Detection | None:
        """Render ``window`` and detect there: the detection in full-frame pixels, or None
        (a miss, :func:`stands_for_frame`).  ``retake``: of the instant just taken."""
        seen = detector(self._take(camera, window, retake=retake))
        return stands_for_frame(seen, window, self.image_sizes_px[camera], expected_area_px)

    def _preview_window(self, camera: int, detector: object, binning: int = 0) -> Window | None:
        """Render a preview of ``camera``'s whole view binned b x b (``binning``, default
        ``config.preview_binning``) and return the window where it shows the target (a
        blob's, or a whole pattern's box), or None (not found, or a window barely cheaper
        than the frame: a full frame follows)."""
        config = self.config
        b = binning or config.preview_binning
        assert callable(detector)
        seen = detector(self._take(camera, binning=b))
        if not isinstance(seen, Detection) or not seen.found or seen.uv is None:
            return None
        # Its position in the full frame is good to about b px.
        u, v = unbinned_px(seen.uv, b)
        uv_px = (float(u), float(v))
        size_px = self.image_sizes_px[camera]
        if seen.extent_px is not None:  # a pattern: its box, from the feature
            left, top, right, bottom = (b * e for e in seen.extent_px)
            return pattern_window(
                size_px, uv_px, (left, top, right, bottom), 4.0 * b, config.window_margin_px
            )
        return expected_window(
            size_px, uv_px, b * b * seen.area_px, 4.0 * b, config.window_margin_px
        )

    def _look_again(
        self, camera: int, detector: object, report: Callable[[Window], Detector]
    ) -> tuple[Detection | None, bool]:
        """After a window placed from an earlier sight missed (the target moved, or the
        window shows something else): ``detector``'s blob found again in a binned preview,
        and detected (by ``report(window)``) in the window the preview places, retaken of
        the same instant.  Returns the detection (None: not in the preview, or that window
        missed too: the full frame follows) and whether that window was rendered."""
        window = self._preview_window(camera, detector)
        if window is None:
            return None, False
        return self._in_window(camera, report(window), window, retake=True), True

    # -- a foveal detector's look: only the window it names ---------------------------
    def _foveal(self, camera: int, detector: FovealDetector, hint: Hint) -> Detection:
        """Render the window ``detector`` names around where the hint puts its point (the
        neck servo's prediction; the eye servo's last sight moved by the gain times the
        eye steps since, with the neck unchanged; else the detector's own last sight)
        and locate it there.  A miss is the detector's answer: no whole frame follows
        (correlation stays foveal inside the loop)."""
        sim, memory = self.sim, self._memory
        eye_steps, neck_rad = sim.eye_encoder_steps(), sim.neck_encoders()
        key: object = detector
        expected_uv_px: tuple[float, float] | None = None
        motion_px = 0.0
        if isinstance(hint, Around):
            expected_uv_px, motion_px = hint.uv_px, hint.motion_px
        elif isinstance(hint, Since):
            key = detector if hint.key is None else hint.key
            seen = memory.sight.get(camera)
            gain_px_per_step = hint.gain_px_per_step
            if (
                seen is not None
                and seen.key == key
                and seen.neck_rad == neck_rad
                and gain_px_per_step is not None
            ):
                motion_px = gain_px_per_step * (eye_steps - seen.eye_steps)
                expected_uv_px = (seen.uv_px[0] + motion_px, seen.uv_px[1])
        size_px = self.image_sizes_px[camera]
        window = detector.search_window(camera, size_px, expected_uv_px, motion_px)
        if (window.width, window.height) == size_px:
            image = self._take(camera)
        else:
            self.counts.window_renders += 1
            image = self._take(camera, window)
        detection = detector.locate(camera, image, (window.x0, window.y0))
        if self._report:
            self.sink.emit(Detected(camera, detection.status, detection.uv))
        if detection.found and detection.uv is not None:
            memory.sight[camera] = Sight(key, eye_steps, neck_rad, detection.uv, detection.area_px)
            memory.extent_px[camera] = None
        else:
            memory.sight.pop(camera, None)
        return detection

    # -- the eye servo's look: predicted from the last sight -------------------------
    def _since(self, camera: int, detector: Detector, hint: Since) -> Detection:
        """With windows on, and when this camera last saw the same target (``key``,
        default the detector) with the neck unchanged since and a gain known, only a
        window is rendered: around where the head expects the target from that sight and
        the eye steps moved since (u + gain * steps), of half-side 3 blob radii plus the
        margin and a quarter of the predicted motion (blob detectors), or the pattern's
        box so grown.  With no gain known yet (the servo's probe), a blob's window is the
        band of rows around that sight (:func:`band_window`): a window's pixels are the
        frame's crop, so it gives the frame's answer at a fraction of its cost.  A blob's
        miss is looked for again in a preview, then in the same instant's full frame.  A
        new blob is first found in a binned preview; ``preview=False`` renders the full
        frame instead (a search's look)."""
        key = detector if hint.key is None else hint.key
        sim, cfg, counts = self.sim, self.config, self.counts
        eye_steps, neck_rad = sim.eye_encoder_steps(), sim.neck_encoders()
        feature = pattern_feature(key)
        if feature is not None:  # a pattern's features share their windows
            key = feature.window_key
        window = None
        if feature is not None or finds_blob(key):
            window = self._window(camera, key, eye_steps, neck_rad, hint.gain_px_per_step)
        # A blob's window placed from the last sight of it: a guess the image confirms.
        guessed_area_px = (
            self._memory.sight[camera].area_px if window is not None and feature is None else None
        )
        if hint.preview and window is None and feature is None and finds_blob(key):
            window = self._blob_preview(camera, key, neck_rad)
        detection = None
        if window is not None:
            counts.window_renders += 1
            detection = self._in_window(
                camera, reporting(detector, self.sink, camera, window), window, guessed_area_px
            )
            if detection is None:
                counts.window_misses += 1
            if (
                detection is None
                and guessed_area_px is not None
                and hint.preview
                and cfg.preview_binning > 1
            ):
                counts.previews += 1
                report = partial(reporting, detector, self.sink, camera)
                detection, rendered = self._look_again(camera, key, report)
                counts.window_renders += rendered
                counts.window_misses += rendered and detection is None
            if detection is None:
                # the same instant, whole
                detection = reporting(detector, self.sink, camera)(self._take(camera, retake=True))
        if detection is None:
            detection = reporting(detector, self.sink, camera)(self._take(camera))
        memory = self._memory
        # Only detections with a centroid and an area predict a window.
        if isinstance(detection, Detection) and detection.found and detection.uv is not None:
            memory.sight[camera] = Sight(key, eye_steps, neck_rad, detection.uv, detection.area_px)
            memory.extent_px[camera] = detection.extent_px
        else:
            memory.sight.pop(camera, None)
        return detection

    def _blob_preview(
        self, camera: int, key: object, neck_rad: tuple[float, float]
    ) -> Window | None:
        """A preview's window for ``key``'s blob where no sight predicts where it is (a
        new target, or the neck moved since)."""
        seen = self._memory.sight.get(camera)
        if not self.config.windows or self.config.preview_binning <= 1:
            return None
        if seen is not None and seen.key == key and seen.neck_rad == neck_rad:
            return None
        self.counts.previews += 1
        return self._preview_window(camera, key)

    def _window(
        self,
        camera: int,
        key: object,
        eye_steps: int,
        neck_rad: tuple[float, float],
        gain_px_per_step: float | None,
    ) -> Window | None:
        """Where to look for ``key``'s target in ``camera`` (None: the full frame): around
        where the last sight puts it, the whole pattern's box for a pattern; with no gain
        learnt yet, a blob's band of rows (:func:`band_window`)."""
        cfg, memory = self.config, self._memory
        seen = memory.sight.get(camera)
        if not cfg.windows or seen is None:
            return None
        if seen.key != key or seen.neck_rad != neck_rad:
            return None
        size_px = self.image_sizes_px[camera]
        extent_px = memory.extent_px.get(camera)
        if gain_px_per_step is None:  # the eyes moved by an image motion not known yet
            if extent_px is not None:
                return None
            return band_window(size_px, seen.uv_px, seen.area_px, cfg.window_margin_px)
        motion_px = gain_px_per_step * (eye_steps - seen.eye_steps)
        expected_uv_px = (seen.uv_px[0] + motion_px, seen.uv_px[1])
        margin_px = cfg.window_margin_px
        if extent_px is not None:  # a pattern: the whole of it
            return pattern_window(size_px, expected_uv_px, extent_px, motion_px, margin_px)
        return expected_window(size_px, expected_uv_px, seen.area_px, motion_px, margin_px)


__all__ = [
    "AREA_CHANGE",
    "Anew",
    "Around",
    "BlobDetector",
    "FovealDetector",
    "Glance",
    "Hint",
    "LookCounts",
    "Looker",
    "PatternFeature",
    "Sight",
    "Since",
    "Whole",
    "band_window",
    "expected_window",
    "finds_blob",
    "foveal_detector",
    "look_once",
    "pattern_feature",
    "pattern_window",
    "reporting",
    "stands_for_frame",
    "unbinned_px",
]
