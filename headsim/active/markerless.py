"""Markerless detectors for the servos: camera 1's fovea tracked from a click, and the
point camera 2 sees there found by correlation in the band the belief predicts.

Both take only images, the click pixel and the head's belief (a band provider built
from encoders and :class:`~headsim.active.measurement.HeadKnowledge`); nothing of the
scene.  Both are :class:`~headsim.active.look.FovealDetector`\\ s: the looker renders
only the window they name (the fovea grown by the search radius, or the band's
rectangle), and correlation runs on that window.  Called on a whole frame they cut
the same window out of it, so correlation stays foveal there too.

Every match is kept (``matches``) with its score and ambiguity, and the detection
carries them, also when the match is refused: a confident wrong match stays visible.
A :class:`MarkerlessPair` given a sink reports each match with its template
(:class:`~headsim.active.events.Matched`: for the recording).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from headsim.active.events import Matched
from headsim.sim.events import EventSink, NoEvents
from headsim.sim.render import Window
from headsim.vision.correspondence import (
    Band,
    Match,
    MatchConfig,
    MatchStatus,
    Template,
    Tracker,
    around,
    cut_template,
    find,
)
from headsim.vision.detection import Detection, DetectionStatus

_STATUS = {
    MatchStatus.OK: DetectionStatus.FOUND,
    MatchStatus.LOW_TEXTURE: DetectionStatus.LOW_TEXTURE,
    MatchStatus.AMBIGUOUS: DetectionStatus.AMBIGUOUS,
    MatchStatus.OCCLUDED: DetectionStatus.OCCLUDED,
    MatchStatus.LOST: DetectionStatus.LOST,
}


def as_detection(match: Match, half_px: int) -> Detection:
    """A match as the servos' detection: FOUND with ``uv`` only when OK; the score and
    the ambiguity always.  ``extent_px`` is the template's box."""
    found = match.status is MatchStatus.OK
    side = 2 * half_px + 1
    return Detection(
        status=_STATUS[match.status],
        uv=match.uv if found else None,
        area_px=float(side * side) if found else 0.0,
        extent_px=(-half_px, -half_px, half_px, half_px) if found else None,
        score=match.score,
        ambiguity=match.ambiguity,
    )


def _window(rect: tuple[int, int, int, int] | None, grow_px: int, size: tuple[int, int]) -> Window:
    """The rectangle (x0, y0, x1, y1) grown by ``grow_px`` and clipped to the image."""
    width, height = size
    if rect is None:
        return Window(0, 0, width, height)
    x0, y0 = max(rect[0] - grow_px, 0), max(rect[1] - grow_px, 0)
    x1, y1 = min(rect[2] + grow_px, width), min(rect[3] + grow_px, height)
    return Window(x0, y0, max(x1 - x0, 1), max(y1 - y0, 1))


def _crop(image: np.ndarray, window: Window) -> np.ndarray:
    return image[window.y0 : window.y1, window.x0 : window.x1]


class TemplateTracker:
    """Camera 1's detector: the fovea around the click in camera 1's first image (or a
    window of it whose top-left is ``origin_px``), tracked
    (:class:`~headsim.vision.correspondence.Tracker`, drift-controlled).

    ``search_radius_px``: how far from the predicted point a look searches, when the
    looker predicts it (the eye steps since the last sight times the gain);
    ``reacquire_radius_px``: how far from the last sight, when nothing predicts the
    motion (the first look, or the neck moved)."""

    def __init__(
        self,
        first_image: np.ndarray,
        click_uv: tuple[float, float],
        config: MatchConfig | None = None,
        search_radius_px: float = 12.0,
        reacquire_radius_px: float = 48.0,
        origin_px: tuple[int, int] = (0, 0),
    ) -> None:
        self.config = config or MatchConfig()
        template = cut_template(first_image, click_uv, self.config, origin_px)
        self.tracker = Tracker(template, self.config)
        self.uv = (float(click_uv[0]), float(click_uv[1]))
        self.search_radius_px = search_radius_px
        self.reacquire_radius_px = reacquire_radius_px
        self.matches: list[Match] = []
        self._band: Band | None = None

    @property
    def template(self) -> Template:
        """The reference template, cut at the click."""
        return self.tracker.original

    def search_window(
        self,
        camera: int,
        image_size_px: tuple[int, int],
        expected_uv_px: tuple[float, float] | None,
        motion_px: float = 0.0,
    ) -> Window:
        """The window the next look needs: the disc to search (around ``expected_uv_px``,
        ``search_radius_px`` plus a quarter of the predicted ``motion_px``, as the
        looker's blob windows; else the last sight's ``reacquire_radius_px``) grown by
        the template's half-side and the fit's pixel.
        ``camera``: the camera looking (this tracker follows one camera's fovea)."""
        if expected_uv_px is None:
            self._band = around(self.uv, self.reacquire_radius_px)
        else:
            self._band = around(expected_uv_px, self.search_radius_px + 0.25 * abs(motion_px))
        return _window(self._band.rect(image_size_px), self.config.half_px + 2, image_size_px)

    def locate(self, camera: int, image: np.ndarray, origin_px: tuple[int, int]) -> Detection:
        """The tracked point in ``image`` (a window whose top-left is ``origin_px`` in
        the full frame), in full-frame pixels, searched where :meth:`search_window`
        said (else around the last sight)."""
        band = self._band or around(self.uv, self.reacquire_radius_px)
        self._band = None
        match = self.tracker.track(image, band, origin_px)
        self.matches.append(match)
        if match.ok and match.uv is not None:
            self.uv = match.uv
        return as_detection(match, self.config.half_px)

    def __call__(self, image: np.ndarray) -> Detection:
        """On a whole frame: only the search window around the last sight is correlated."""
        size = (image.shape[1], image.shape[0])
        window = self.search_window(1, size, None)
        return self.locate(1, _crop(image, window), (window.x0, window.y0))


class CorrespondenceFinder:
    """Camera 2's detector: camera 1's foveal template (cut at fixation, or at the
    click) found in camera 2's image within the band ``band()`` predicts (the head's
    belief at the current encoders, :func:`~headsim.vision.correspondence.epipolar_band`).
    A look near an earlier OK match searches only ``search_radius_px`` around the
    looker's prediction, inside the band."""

    def __init__(
        self,
        template: Template,
        band: Callable[[], Band],
        config: MatchConfig | None = None,
        search_radius_px: float = 12.0,
    ) -> None:
        self.config = config or MatchConfig()
        self.template = template
        self.band = band
        self.search_radius_px = search_radius_px
        self.matches: list[Match] = []
        self._next: Band | None = None

    @classmethod
    def from_view(
        cls,
        image1: np.ndarray,
        uv1: tuple[float, float],
        band: Callable[[], Band],
        config: MatchConfig | None = None,
    ) -> CorrespondenceFinder:
        """A finder of the point at ``uv1`` px in camera 1's ``image1`` (its fovea)."""
        config = config or MatchConfig()
        return cls(cut_template(image1, uv1, config), band, config)

    def search_window(
        self,
        camera: int,
        image_size_px: tuple[int, int],
        expected_uv_px: tuple[float, float] | None,
        motion_px: float = 0.0,
    ) -> Window:
        """The band's rectangle (or, with ``expected_uv_px`` inside the band, the disc of
        ``search_radius_px`` there), grown by the template's half-side and a pixel."""
        band = self.band()
        if expected_uv_px is not None and self.matches and self.matches[-1].ok:
            near = around(expected_uv_px, self.search_radius_px + 0.25 * abs(motion_px))
            inside = band.distance_px(np.array(expected_uv_px[0]), np.array(expected_uv_px[1]))
            if float(inside) <= band.tolerance_px:
                band = Band(near.points_uv, near.tolerance_px)
        self._next = band
        return _window(band.rect(image_size_px), self.config.half_px + 2, image_size_px)

    def locate(self, camera: int, image: np.ndarray, origin_px: tuple[int, int]) -> Detection:
        """The corresponding point in ``image`` (a window whose top-left is
        ``origin_px``), full-frame pixels."""
        band = self._next or self.band()
        self._next = None
        match = find(self.template, image, band, self.config, origin_px)
        self.matches.append(match)
        return as_detection(match, self.config.half_px)

    def __call__(self, image: np.ndarray) -> Detection:
        """On a whole frame: only the band's rectangle is correlated."""
        size = (image.shape[1], image.shape[0])
        window = self.search_window(2, size, None)
        return self.locate(2, _crop(image, window), (window.x0, window.y0))


#: The head's belief, asked at camera 1's look: camera 1's point (u, v) px then ->
#: the band camera 2 should search, evaluated at camera 2's look (the ray fixed in the
#: head or world frame with the encoders of camera 1's look, projected into camera 2
#: with the encoders of camera 2's; :func:`~headsim.vision.correspondence.epipolar_band`).
BandFor = Callable[[tuple[float, float]], Callable[[], Band]]


class MarkerlessPair:
    """One target's detector for both cameras, for procedures that hand one detector
    to the servos (Model 2, Model 1): camera 1 tracks the fovea clicked in its first
    image (:class:`TemplateTracker`; a window of it at ``origin_px`` will do); camera 2 finds camera 1's latest foveal template
    (cut at camera 1's last confident match, so at fixation once camera 1 fixates) in
    the band ``band_for`` gives for camera 1's last point.  Model 2's images of the
    camera that is not centred come from the same two: camera 2's at step 1 from the
    correspondence, camera 1's at step 2 from the tracker.

    Through the :class:`~headsim.active.look.Looker` (a
    :class:`~headsim.active.look.FovealDetector`) only; called on an image alone it
    cannot tell the camera and says LOST (a binned preview of a scan: the template is
    at full scale).  ``sink``: where each match is reported (:class:`Matched`)."""

    def __init__(
        self,
        first_image1: np.ndarray,
        click_uv: tuple[float, float],
        band_for: BandFor,
        config: MatchConfig | None = None,
        origin_px: tuple[int, int] = (0, 0),
        sink: EventSink | None = None,
    ) -> None:
        self.config = config or MatchConfig()
        self.band_for = band_for
        self.sink = sink or NoEvents()
        self.tracker = TemplateTracker(first_image1, click_uv, self.config, origin_px=origin_px)
        self.finder = CorrespondenceFinder(
            self.tracker.template, band_for(self.tracker.uv), self.config
        )

    def _camera2(self) -> CorrespondenceFinder:
        self.finder.template = self.tracker.tracker.current
        return self.finder

    def search_window(
        self,
        camera: int,
        image_size_px: tuple[int, int],
        expected_uv_px: tuple[float, float] | None,
        motion_px: float = 0.0,
    ) -> Window:
        """The window ``camera``'s next look needs (tracker's, or the band's)."""
        if camera == 1:
            return self.tracker.search_window(camera, image_size_px, expected_uv_px, motion_px)
        return self._camera2().search_window(camera, image_size_px, expected_uv_px, motion_px)

    def locate(self, camera: int, image: np.ndarray, origin_px: tuple[int, int]) -> Detection:
        """``camera``'s point in ``image`` (top-left ``origin_px``), full-frame pixels."""
        if camera == 1:
            detection = self.tracker.locate(camera, image, origin_px)
            self.sink.emit(Matched(1, self.tracker.matches[-1], self.tracker.template))
            if detection.found and detection.uv is not None:
                self.finder.band = self.band_for(detection.uv)
            return detection
        finder = self._camera2()
        detection = finder.locate(camera, image, origin_px)
        self.sink.emit(Matched(2, finder.matches[-1], finder.template))
        return detection

    def __call__(self, image: np.ndarray) -> Detection:
        """An image without its camera: nothing can be said (LOST, no score)."""
        return Detection(DetectionStatus.LOST, None, 0.0)


__all__ = ["BandFor", "CorrespondenceFinder", "MarkerlessPair", "TemplateTracker", "as_detection"]
