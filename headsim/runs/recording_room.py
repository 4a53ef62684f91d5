"""What a room run (``[scene.room]``, markerless targets) adds to the recording: each
eye's fovea at every image, camera 1's template and camera 2's matched patch, the match
scores over time and each match's status as text, and at each fixation the rays from
each eye's true optical centre to where its goal ray landed.

Entity paths (docs/how-to/record.md lists them):

- ``/fovea/cam1/image``, ``/fovea/cam2/image``: a :data:`FOVEA_HALF_PX` crop of each
  image as shown around where the eye looks: its goal column, on the row of its last
  match (the row its goal ray is cast on; the believed centre row before any), and at
  each measurement again the crop of the look that fixated (a match within
  :data:`FIXATED_PX` of the goal column), so a fixation's foveas are what stays on
  screen; ``/fovea/camN/match``: the match's template box there (green OK, red refused);
- ``/fovea/cam1/template``: camera 1's template (its fovea at the click, grey);
  ``/fovea/cam2/patch``: camera 2's image where its match landed, the template's size;
- ``/correlation/camN/score``, ``/correlation/camN/ambiguity`` (scalars) and
  ``/correlation/status`` (a text log: camera, status, score, ambiguity);
- ``/world/landing/rays`` (each eye's goal ray from its true centre to the point it
  landed on, or 3 m where it hit nothing), ``/world/landing/points`` (the landed points)
  and ``/world/landing/targets`` (the intended ones): cyan camera 1, magenta camera 2,
  red a false fixation (:mod:`headsim.runs.surface`), every fixation so far.

The landings are truth (:class:`headsim.runs.surface.LandingLog`, the scorer's own rule):
for the record only.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np
import rerun as rr

from headsim.active.events import Detected, FixationStarted, Matched, PhaseStarted
from headsim.active.measurement import HeadKnowledge
from headsim.runs.events import MeasurementRecorded, Stamp
from headsim.runs.landing import Landing
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.recording_layout import (
    FOVEA_HALF_PX,
    GREEN,
    ORANGE,
    RED,
    UI_RADIUS,
    UI_RADIUS_SMALL,
)
from headsim.runs.surface import LandingLog
from headsim.sim import names
from headsim.sim.simulator import HeadSim
from headsim.vision.correspondence import MatchStatus, Template

#: A match this close to the goal column, px, is a fixation (the servos stop within it).
FIXATED_PX = 1.0
#: Each eye's colour for its rays and landed points.
EYE_COLOURS = ((40, 200, 235), (225, 70, 215))
#: How far a ray that hit nothing is drawn, m.
MISSED_RAY_M = 3.0

Later = Callable[..., None]


def crop(image: np.ndarray, centre_uv: tuple[float, float], half_px: int) -> np.ndarray:
    """The (2 half + 1)-pixel square of ``image`` around the pixel nearest ``centre_uv``,
    black where it runs off the image."""
    u, v = (round(c) for c in centre_uv)
    side = 2 * half_px + 1
    out = np.zeros((side, side, *image.shape[2:]), dtype=image.dtype)
    height, width = image.shape[:2]
    x0, y0 = u - half_px, v - half_px
    sx0, sy0 = max(x0, 0), max(y0, 0)
    sx1, sy1 = min(x0 + side, width), min(y0 + side, height)
    if sx1 > sx0 and sy1 > sy0:
        out[sy0 - y0 : sy1 - y0, sx0 - x0 : sx1 - x0] = image[sy0:sy1, sx0:sx1]
    return out


def template_image(template: Template) -> np.ndarray:
    """A template's grey levels as an 8-bit image."""
    return np.clip(np.rint(template.patch), 0, 255).astype(np.uint8)


class RoomRecording:
    """The room's entities, logged to ``rec`` by the :class:`~headsim.runs.recording.Recorder`
    (which hands on the events); ``later(fn, *args)`` runs ``fn`` on the recording's
    thread (JPEG encoding), after what was given before."""

    def __init__(self, rec: rr.RecordingStream, later: Later, jpeg_quality: int) -> None:
        self.rec = rec
        self.later = later
        self.jpeg_quality = jpeg_quality
        self.sim: HeadSim | None = None
        self.goal_uv: dict[int, tuple[float, float]] = {}
        self.landings: LandingLog | None = None
        self._last_image: dict[int, np.ndarray] = {}
        #: Each camera's fovea in its last image: (crop, its top-left px in the image).
        self._fovea: dict[int, tuple[np.ndarray, tuple[int, int]]] = {}
        #: Each camera's row of its last match, px (where its goal ray is cast).
        self._row: dict[int, float] = {}
        #: Each camera's last fixated fovea since the last measurement, with the box centre.
        self._fixated: dict[int, tuple[np.ndarray, tuple[float, float], int]] = {}
        self._template: int | None = None
        self._rays: list[tuple[np.ndarray, np.ndarray]] = []
        self._ray_colours: list[tuple[int, int, int]] = []
        self._points: list[np.ndarray] = []
        self._point_colours: list[tuple[int, int, int]] = []
        self._targets: list[np.ndarray] = []
        self._target_labels: list[str] = []
        self._log_static()

    def _log_static(self) -> None:
        for cam, colour in zip(names.CAMERAS, EYE_COLOURS, strict=True):
            # Each eye's colour; its ambiguity darker, as a cross.
            dark = tuple(c // 2 for c in colour)
            shapes = rr.components.MarkerShape
            for key, shade, marker in (
                ("score", colour, shapes.Circle),
                ("ambiguity", dark, shapes.Cross),
            ):
                self.rec.log(
                    f"/correlation/{cam}/{key}",
                    rr.SeriesPoints(
                        names=[f"{cam} {key}"], colors=[shade], markers=[marker], marker_sizes=[3.0]
                    ),
                    static=True,
                )

    # -- the events the recorder hands on ---------------------------------------------
    def notify(self, event: object, at: Stamp) -> None:
        """The run's events (images come through :meth:`image`, as shown)."""
        if isinstance(event, PhaseStarted):
            self.phase(event.name, event.sim, event.knowledge)
        elif isinstance(event, FixationStarted):
            self.fixation()
        elif isinstance(event, Detected):
            if self.landings is not None:
                self.landings.notify(event, at)
        elif isinstance(event, Matched):
            self.matched(event)
        elif isinstance(event, MeasurementRecorded):
            self.measured(event.record, at.frame)

    def phase(self, name: str, sim: HeadSim, knowledge: HeadKnowledge) -> None:
        """A phase begins: the goal points, and (measuring) the landings' log."""
        self.sim, self._last_image, self._fovea, self._row = sim, {}, {}, {}
        self._fixated = {}
        self.goal_uv = {c: knowledge.reference(sim, c) for c in (1, 2)}
        goal_u = (self.goal_uv[1][0], self.goal_uv[2][0])
        self.landings = LandingLog(sim, goal_u) if name == "measurement" else None

    def fixation(self) -> None:
        if self.landings is not None:
            self.landings.clear()

    def image(self, camera: int, image: np.ndarray, frame: int, step: int) -> None:
        """An image as shown: its fovea, a crop around where the eye looks."""
        self._last_image[camera] = image
        goal = self.goal_uv.get(camera)
        if goal is None:
            return
        centre = (round(goal[0]), round(self._row.get(camera, goal[1])))
        fovea = crop(image, centre, FOVEA_HALF_PX)
        self._fovea[camera] = fovea, (centre[0] - FOVEA_HALF_PX, centre[1] - FOVEA_HALF_PX)
        path = f"/fovea/{names.CAMERAS[camera - 1]}/image"
        self.later(self._log_jpeg, path, fovea, frame, step)

    def _log_jpeg(self, path: str, image: np.ndarray, frame: int, step: int) -> None:
        log_jpeg(self.rec, path, image, frame, step, self.jpeg_quality)

    def matched(self, event: Matched) -> None:
        """A match (logged at the recorder's current time): its box in the fovea, camera
        1's template or camera 2's patch, the scores and the status."""
        cam = names.CAMERAS[event.camera - 1]
        match, half = event.match, event.template.half_px
        ok = match.status is MatchStatus.OK
        fovea = self._fovea.get(event.camera)
        box = None
        if match.uv is not None and fovea is not None:
            origin = fovea[1]
            box = (match.uv[0] - origin[0], match.uv[1] - origin[1])
            if not all(-half <= c <= 2 * FOVEA_HALF_PX + half for c in box):
                box = None  # the match lies outside the fovea
        self._log_box(cam, box, half, ok, match.status.value)
        goal = self.goal_uv.get(event.camera)
        if ok and match.uv is not None and goal is not None:
            self._row[event.camera] = match.uv[1]
            if fovea is not None and box is not None and abs(match.uv[0] - goal[0]) <= FIXATED_PX:
                self._fixated[event.camera] = (fovea[0], box, half)
        if event.camera == 1:
            if self._template != id(event.template):
                self._template = id(event.template)
                self.rec.log("/fovea/cam1/template", rr.Image(template_image(event.template)))
        elif match.uv is not None and 2 in self._last_image:
            patch = crop(self._last_image[2], match.uv, half)
            self.rec.log("/fovea/cam2/patch", rr.Image(patch))
        self.rec.log(f"/correlation/{cam}/score", rr.Scalars([float(match.score)]))
        self.rec.log(f"/correlation/{cam}/ambiguity", rr.Scalars([float(match.ambiguity)]))
        self.rec.log(
            "/correlation/status",
            rr.TextLog(
                f"{cam} {match.status.value}: score {match.score:.3f}, "
                f"ambiguity {match.ambiguity:.3f}",
                level=rr.TextLogLevel.INFO if ok else rr.TextLogLevel.WARN,
            ),
        )

    def _log_box(
        self, cam: str, centre: tuple[float, float] | None, half_px: int, ok: bool, text: str
    ) -> None:
        """The match's template box (half side ``half_px``) in the camera's fovea (None:
        none there)."""
        if centre is None:
            self.rec.log(f"/fovea/{cam}/match", rr.Clear(recursive=False))
            return
        self.rec.log(
            f"/fovea/{cam}/match",
            rr.Boxes2D(
                centers=[centre],
                half_sizes=[[half_px + 0.5, half_px + 0.5]],
                colors=[GREEN if ok else RED],
                labels=[text],
                show_labels=False,
            ),
        )

    def measured(self, record: MeasurementRecord, frame: int) -> None:
        """A fixation scored: each eye's fovea where it fixated (shown again), its ray to
        where it landed, the landed points and the intended target, added to those of
        the fixations before (false ones red)."""
        for camera, (fovea, box, half) in sorted(self._fixated.items()):
            cam = names.CAMERAS[camera - 1]
            self.later(self._log_jpeg, f"/fovea/{cam}/image", fovea, frame, record.step)
            self._log_box(cam, box, half, True, "fixated")
        self._fixated = {}
        if self.landings is None or record.fixation is None:
            return
        landed = self.landings.fixations(record.measurement)
        false = record.fixation.false_fixation
        for camera, look in sorted(landed.items()):
            landing = look.landing
            colour = RED if false else EYE_COLOURS[camera - 1]
            self._rays.append((landing.origin_world_m, _end(landing)))
            self._ray_colours.append(colour)
            if landing.point_world_m is not None:
                self._points.append(landing.point_world_m)
                self._point_colours.append(colour)
        truth = record.measurement.truth_world_m
        if truth is not None and np.all(np.isfinite(truth)):
            self._targets.append(np.asarray(truth, dtype=float))
            self._target_labels.append(record.measurement.name + (" (false)" if false else ""))
        if self._rays:
            self.rec.log(
                "/world/landing/rays",
                rr.LineStrips3D(
                    [np.array(r) for r in self._rays],
                    colors=self._ray_colours,
                    radii=rr.components.Radius.ui_points(1.5),
                ),
            )
        if self._points:
            self.rec.log(
                "/world/landing/points",
                rr.Points3D(self._points, radii=UI_RADIUS, colors=self._point_colours),
            )
        if self._targets:
            self.rec.log(
                "/world/landing/targets",
                rr.Points3D(
                    self._targets,
                    radii=UI_RADIUS_SMALL,
                    colors=[ORANGE] * len(self._targets),
                    labels=self._target_labels,
                    show_labels=False,
                ),
            )


def log_jpeg(
    rec: rr.RecordingStream, path: str, image: np.ndarray, frame: int, step: int, quality: int
) -> None:
    """An RGB image logged at ``path`` as a JPEG of ``quality``, at its frame and step."""
    ok, jpeg = cv2.imencode(
        ".jpg", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, quality]
    )
    if ok:
        rec.set_time("frame", sequence=frame)
        rec.set_time("step", sequence=step)
        rec.log(path, rr.EncodedImage(contents=jpeg.tobytes(), media_type="image/jpeg"))


def _end(landing: Landing) -> np.ndarray:
    """Where a ray is drawn to: its landed point, else :data:`MISSED_RAY_M` along it."""
    if landing.point_world_m is not None:
        return np.asarray(landing.point_world_m, dtype=float)
    return landing.origin_world_m + MISSED_RAY_M * landing.direction_world


__all__ = ["EYE_COLOURS", "FOVEA_HALF_PX", "RoomRecording", "crop", "template_image"]
