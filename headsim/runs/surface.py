"""Markerless targets on the room's surfaces, as the runner measures them (``[scene.room]
targets``): drawn at the start pose from the seed, told to the head by a click in camera
1's image, fixated through a :class:`~headsim.active.markerless.MarkerlessPair`, and
scored by where each eye's goal ray truly landed.

The head is given only the click, the images and its belief: the pair's band along
camera 1's row of the point +- ``band_px`` in camera 2, from the believed reference
rows (a head that knows no focal length).  The truth (the drawn point, the click's true
projection, the landings) is for placing, the click and scoring only.

A fixation is **false** when the measurement says ok but either eye's goal ray landed
more than :func:`false_fixation_limit_m` (1 % of the target's depth, at least 5 mm) from
the intended target, or on nothing: a tracker that slid off (eye 1) or a confident wrong
correspondence (eye 2), counted, not hidden.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TypeVar

import numpy as np

from headsim.active.events import Detected, PhaseStarted
from headsim.active.markerless import MarkerlessPair
from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.head.servo_head import ServoHead
from headsim.head.sim_head import SimHead
from headsim.runs.context import PARKED_WORLD_M, record_measurement, simulator
from headsim.runs.events import Hub, Stamp
from headsim.runs.landing import Landing, fixation_error, landing, vergence_error_deg
from headsim.runs.outcomes import (
    FALSE_FIXATION_FRACTION,
    FALSE_FIXATION_MIN_M,
    FixationScore,
    MeasurementRecord,
    SurfaceDraw,
    by_texture,
    fixation_stats,
)
from headsim.runs.targets import marker_target
from headsim.runs.texture_class import TEXTURE_CLASSES, texture_class, texture_kinds
from headsim.scenario.spec import (
    MARKER_BODIES,
    STREAM_CLICKS,
    STREAM_SURFACE_TARGETS,
    Scenario,
    SurfaceTargetsSpec,
)
from headsim.scenario.surface_targets import (
    Click,
    NotOnSurface,
    SurfaceTarget,
    click,
    draw_targets,
    in_image,
    on_object,
    on_surface,
    point_world,
    surface_normal,
    visible,
)
from headsim.sim import names
from headsim.sim.render import Window
from headsim.sim.simulator import HeadSim
from headsim.vision.correspondence import Band, Match, MatchConfig, row_band

#: The marker the twin puts at each point (the default scene's; 4 mm in radius) ...
TWIN_MARKER = names.MARKERS[0]
#: ... its centre this far out from the surface along the normal, m: 1 mm clear of it.
MARKER_OFFSET_M = 0.005


def false_fixation_limit_m(depth_m: float) -> float:
    """How far an eye's landed point may lie from the target before the fixation is false, m."""
    return max(FALSE_FIXATION_FRACTION * depth_m, FALSE_FIXATION_MIN_M)


@dataclass(frozen=True)
class Look:
    """One look that found the target, as :class:`LandingLog` keeps it: the ``camera``,
    every motor's ``encoders`` then, the goal ray's ``landing``, where the look saw the
    target ``seen_uv`` and where it truly was in that image ``true_uv`` (px; None: no
    target set)."""

    camera: int
    encoders: tuple[int, ...]
    landing: Landing
    seen_uv: tuple[float, float]
    true_uv: tuple[float, float] | None

    @property
    def error_px(self) -> float:
        """|seen - true|, px (NaN without a true position)."""
        return math.nan if self.true_uv is None else math.dist(self.seen_uv, self.true_uv)


class LandingLog:
    """A run subscriber (truth, for scoring): at each look that found the target, that
    camera's goal ray (its goal column ``goal_u``, on the row the look saw the target) at
    the camera's true pose then, cast into the scene, kept with the encoder readings of
    that pose and the target's true pixel in that image (``target``: its true position
    now, set per target).  The servos are not touched: they report their looks as events."""

    def __init__(self, sim: HeadSim, goal_u: tuple[float, float]) -> None:
        self.sim = sim
        self.goal_u = goal_u
        self.looks: list[Look] = []
        self.target: Callable[[], np.ndarray] | None = None

    def clear(self, target: Callable[[], np.ndarray] | None = None) -> None:
        self.looks = []
        self.target = target

    def encoders(self) -> tuple[int, ...]:
        """Every motor's encoder reading now, whole steps, in ``sim.motors`` order."""
        return tuple(self.sim.encoder_steps(motor) for motor in self.sim.motors)

    def notify(self, event: object, at: Stamp) -> None:
        if isinstance(event, Detected) and event.uv_px is not None:
            goal = (self.goal_u[event.camera - 1], event.uv_px[1])
            true_uv = None
            if self.target is not None:
                u, v = self.sim.truth.project(self.target()[None, :], event.camera)[0]
                true_uv = (float(u), float(v))
            seen = (float(event.uv_px[0]), float(event.uv_px[1]))
            self.looks.append(
                Look(
                    event.camera,
                    self.encoders(),
                    landing(self.sim, event.camera, goal),
                    seen,
                    true_uv,
                )
            )

    def last(self, camera: int, where: Callable[[tuple[int, ...]], bool]) -> Look | None:
        """``camera``'s last look at a pose whose encoders satisfy ``where``."""
        for look in reversed(self.looks):
            if look.camera == camera and where(look.encoders):
                return look
        return None

    def fixations(self, m: Measurement) -> dict[int, Look]:
        """Each camera's look where its servo left it fixated: Model 2's camera 1 at step
        1's eye encoder, camera 2 at step 2's; Model 1's both at the final pose; the
        one-step fixation's each at its own eye motor's and the neck's final encoders."""
        out: dict[int, Look] = {}
        if not m.ok:
            return out
        if m.method.value == "model2":
            eye = self.sim.motors.index("eye")
            resolution = self.sim.settings.encoder_resolution_rad
            for camera, key in ((1, "step1_encoder_rad"), (2, "step2_encoder_rad")):
                steps = round(m.details[key] / resolution)

                def at_step(encoders: tuple[int, ...], steps: int = steps) -> bool:
                    return encoders[eye] == steps

                found = self.last(camera, at_step)
                if found is not None:
                    out[camera] = found
            return out
        now = self.encoders()
        if m.method.value == "fixation":
            # Each eye's own motor: camera c's view depends on the neck and its eye alone,
            # so its last look at the final pose may precede the other eye's last step.
            return self._per_eye(now)
        for camera in (1, 2):
            found = self.last(camera, lambda e: e == now)
            if found is not None:
                out[camera] = found
        return out

    def _per_eye(self, now: tuple[int, ...]) -> dict[int, Look]:
        """Each camera's last look with the neck and that camera's eye motor (camera
        1: ``eye``, camera 2: ``eye2``) at their encoders ``now``."""
        motors = self.sim.motors
        out: dict[int, Look] = {}
        for camera, eye in ((1, "eye"), (2, "eye2")):
            kept = [k for k, name in enumerate(motors) if name.startswith("neck") or name == eye]

            def same(encoders: tuple[int, ...], kept: list[int] = kept) -> bool:
                return all(encoders[k] == now[k] for k in kept)

            found = self.last(camera, same)
            if found is not None:
                out[camera] = found
        return out


def score_fixation(
    looks: dict[int, Look],
    target_world_m: np.ndarray,
    depth_m: float,
    ok: bool,
    told: Click | None,
    match: Match | None,
    last_match: Look | None = None,
    focal2_px: float = math.nan,
) -> FixationScore:
    """A :class:`FixationScore` from the logged looks at the fixation (an eye missing:
    NaN), the click the head was ``told`` (None: a marker, no click; its error NaN) and
    camera 2's last correspondence ``match``; ``last_match``: camera 2's last confident look
    whatever the outcome, judged wrong beyond the false-fixation limit seen from camera 2
    at ``focal2_px`` (truth's focal length: scoring only)."""
    one, two = (None if (x := looks.get(c)) is None else x.landing for c in (1, 2))
    look_px = [math.nan if (x := looks.get(c)) is None else x.error_px for c in (1, 2)]
    errors = [
        (math.nan, math.nan)
        if x is None
        else (lambda e: (e.angle_deg, e.distance_m))(
            fixation_error(x.origin_world_m, x.direction_world, x.point_world_m, target_world_m)
        )
        for x in (one, two)
    ]
    vergence = math.nan
    if one is not None and two is not None and one.point_world_m is not None:
        vergence = vergence_error_deg(two.origin_world_m, two.direction_world, one.point_world_m)
    limit = false_fixation_limit_m(depth_m)
    match_px = math.nan if last_match is None else last_match.error_px
    # An eye whose ray met nothing is off; an eye without a look at the fixation is unknown.
    false = ok and any(
        x is not None and (math.isnan(off) or off > limit)
        for x, (_, off) in zip((one, two), errors, strict=True)
    )

    def point(x: Landing | None) -> tuple[float, ...] | None:
        return None if x is None or x.point_world_m is None else tuple(map(float, x.point_world_m))

    return FixationScore(
        vergence_error_deg=vergence,
        error_deg=(errors[0][0], errors[1][0]),
        error_m=(errors[0][1], errors[1][1]),
        landed=("" if one is None else one.body, "" if two is None else two.body),
        landed_world_m=(point(one), point(two)),
        click_error_px=math.nan if told is None else math.dist(told.clicked_uv, told.true_uv),
        image_error_px=(look_px[0], look_px[1]),
        match_sigma_px=None if match is None else float(match.template_sigma_px),
        match_score=None if match is None else float(match.score),
        match_ambiguity=None if match is None else float(match.ambiguity),
        match_status=None if match is None else match.status.value,
        false_fixation=bool(false),
        false_fixation_limit_m=limit,
        match_error_px=match_px,
        wrong_match=bool(match_px > limit / depth_m * focal2_px),
    )


def row_band_for(
    knowledge: HeadKnowledge, head: ServoHead, band_px: float
) -> Callable[[tuple[float, float]], Callable[[], Band]]:
    """The band camera 2 searches for camera 1's point at (u, v): camera 1's row shifted
    by the believed reference rows' difference, +- ``band_px``, across camera 2's width
    (the head's belief only; the image size is the image's)."""
    v_shift = knowledge.reference(head, 2)[1] - knowledge.reference(head, 1)[1]
    width = head.camera_settings(2).width

    def band_for(uv1: tuple[float, float]) -> Callable[[], Band]:
        band = row_band(uv1[1] + v_shift, width, band_px)
        return lambda: band

    return band_for


def _start_pose(sim: HeadSim) -> None:
    """Every motor back to 0 (where the targets were drawn and the user clicks)."""
    sim.move(**{motor: 0.0 for motor in sim.motors})


S = TypeVar("S")


def measure_surface_targets(
    scenario: Scenario,
    hub: Hub,
    knowledge: HeadKnowledge,
    label: str,
    servo: Callable[[ServoHead], S],
    measure: Callable[[ServoHead, S, Target, HeadKnowledge], Measurement],
    both_views: bool = False,
) -> tuple[list[MeasurementRecord], SurfaceDraw]:
    """Each of ``[scene.room] targets`` measured in turn from the start pose: listed or
    drawn, clicked in camera 1's image there, measured with ``measure`` through one shared
    ``servo``, its fixation scored from the looks the run reported (:class:`LandingLog`).
    With ``targets_as = "markers"`` (the marker twin) each is instead the ordinary marker
    target: :data:`TWIN_MARKER` put :data:`MARKER_OFFSET_M` out from the point along the
    surface's normal, found by its colour, scored against the marker's centre.
    ``both_views``: only points that camera 2's start image also shows with a template's
    room (a servo whose first look is with both cameras: Model 1, the one-step fixation);
    else camera 2 need only see them."""
    spec = scenario.scene.surface_targets
    assert spec is not None
    records: list[MeasurementRecord] = []
    with simulator(hub, "default", scenario) as sim:
        for body in MARKER_BODIES:  # markers play no part: out of every view
            sim.set_body_pose(body, np.array(PARKED_WORLD_M))
        drawn = _classed(sim, scenario, _draw(sim, spec, scenario.seed, both_views))
        markers_at = [
            np.array(t.point_world_m) + MARKER_OFFSET_M * surface_normal(sim, t.point_world_m)
            if spec.targets_as == "markers"
            else None
            for t in drawn.targets
        ]
        truth = {
            t.name: np.array(t.point_world_m) if at is None else at
            for t, at in zip(drawn.targets, markers_at, strict=True)
        }
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        goal_u = (knowledge.reference(sim, 1)[0], knowledge.reference(sim, 2)[0])
        log = LandingLog(sim, goal_u)
        hub.subscribers.append(log)
        try:
            head = SimHead(sim)  # what the servo and the measurement drive
            shared = servo(head)
            clicks = np.random.default_rng([scenario.seed, STREAM_CLICKS])
            band_for = row_band_for(knowledge, head, spec.band_px)
            for placed, marker_at in zip(drawn.targets, markers_at, strict=True):
                step = hub.begin(placed.name)
                _start_pose(sim)
                log.clear()
                pair: MarkerlessPair | None = None
                if marker_at is not None:
                    # The twin: the ordinary marker target, detected by its colour.
                    sim.set_body_pose(TWIN_MARKER, marker_at)
                    target = marker_target(placed.name, TWIN_MARKER)
                    where = sim.truth.position(TWIN_MARKER)
                    told = None
                else:
                    told = click(sim, np.array(placed.point_world_m), clicks, spec.click_error_px)
                    # The first image: the head needs only the fovea around the click (the
                    # full frame's crop, at a window's cost).
                    fovea = _fovea(sim, told.clicked_uv)
                    first = sim.render_window(1, fovea)
                    origin = (fovea.x0, fovea.y0)
                    pair = MarkerlessPair(
                        first, told.clicked_uv, band_for, origin_px=origin, sink=hub
                    )
                    log.clear(_clicked_point(sim, told, placed))
                    target = Target(placed.name, pair, _true_point(placed))
                    where = point_world(sim, placed.body, placed.point_body_m)
                # Depth at the start pose (a failure leaves the head wherever it gave up).
                truth_head = sim.truth.transform_points(where, "world", "head")[0]
                depth = float(truth_head[2])
                m = measure(head, shared, target, knowledge)
                if not m.ok:
                    m = replace(m, truth_head_m=truth_head)
                match = None
                if pair is not None:
                    # The correspondence the measurement used: camera 2's last confident
                    # match (else its last one, whatever it said).
                    used = [x for x in pair.finder.matches if x.ok] or pair.finder.matches
                    match = used[-1] if used else None
                looks = log.fixations(m)
                if marker_at is not None:
                    looks = {c: _nearest(x, where) for c, x in looks.items()}
                last = log.last(2, lambda encoders: True)
                focal2 = sim.truth.camera_settings(2).kx
                score = score_fixation(looks, where, depth, m.ok, told, match, last, focal2)
                records.append(record_measurement(hub, m, label, step, fixation=score))
            sim.set_body_pose(TWIN_MARKER, np.array(PARKED_WORLD_M))
        finally:
            hub.subscribers.remove(log)
    classes = {t.name: t.texture_class for t in drawn.targets}
    return records, replace(
        drawn,
        measured_as=spec.targets_as,
        stats=fixation_stats(records),
        by_texture=by_texture(records, classes, TEXTURE_CLASSES),
    )


def _classed(sim: HeadSim, scenario: Scenario, drawn: SurfaceDraw) -> SurfaceDraw:
    """``drawn`` with each target's texture class (:mod:`headsim.runs.texture_class`),
    decided at the start pose (truth, for the by-texture table)."""
    room = scenario.scene.room
    kinds = {} if room is None else texture_kinds(room)
    half = MatchConfig().half_px
    return replace(
        drawn,
        targets=tuple(
            replace(
                t, texture_class=texture_class(sim, kinds, t.body, np.array(t.point_world_m), half)
            )
            for t in drawn.targets
        ),
    )


def _nearest(look: Look, centre_world_m: np.ndarray) -> Look:
    """``look`` with its landed point moved to the point of its ray nearest a marker's
    centre: the point the eye fixates (its ray meets the sphere's front, about radius x
    the vergence angle off the other eye's line)."""
    ray = look.landing
    along = float(ray.direction_world @ (centre_world_m - ray.origin_world_m))
    point = ray.origin_world_m + along * ray.direction_world
    return replace(look, landing=replace(ray, point_world_m=point, distance_m=along))


def _fovea(sim: HeadSim, uv: tuple[float, float]) -> Window:
    """Camera 1's window that holds the template around ``uv`` (inside the image)."""
    cam = sim.camera_settings(1)
    return Window.around(uv, MatchConfig().half_px + 2, (cam.width, cam.height))


def _clicked_point(sim: HeadSim, told: Click, placed: SurfaceTarget) -> Callable[[], np.ndarray]:
    """Where the surface point under the click truly is now (call at the start pose): the
    point both eyes' templates hold, so that an eye's image error is its tracker's drift
    or its correspondence's error, apart from the click's.  The target itself when the
    click's ray meets nothing."""
    hit = landing(sim, 1, told.clicked_uv)
    if hit.point_world_m is None or not hit.body:
        return lambda: point_world(sim, placed.body, placed.point_body_m)
    body = sim.data.body(hit.body)
    local = body.xmat.reshape(3, 3).T @ (hit.point_world_m - body.xpos)
    return lambda: point_world(sim, hit.body, local)


def _true_point(placed: SurfaceTarget) -> Callable[[ServoHead], np.ndarray]:
    return lambda head: point_world(head.truth, placed.body, placed.point_body_m)


def _draw(sim: HeadSim, spec: SurfaceTargetsSpec, seed: int, both_views: bool) -> SurfaceDraw:
    """The listed targets, then those drawn at the start pose; none drawn, with the failure,
    when the surfaces in view offer too few (a room and a field that do not meet); none at
    all when a listed one is not on its surface or not in camera 1's start image (the click),
    or, ``both_views``, not in camera 2's with the same margin."""
    asked = spec.count + len(spec.listed)
    # Room for camera 1's template around the click, wherever the click error puts it.
    margin = MatchConfig().half_px + 2 + 4 * spec.click_error_px
    listed = []
    for t in spec.listed:
        try:
            placed = (
                on_surface(sim, t.name, t.point_m)
                if t.body is None
                else on_object(sim, t.name, t.body, t.point_m)
            )
        except NotOnSurface as error:
            return SurfaceDraw(asked, 0, {}, (), failure=f"listed markerless target {error}")
        point = np.array(placed.point_world_m)
        cameras = (1, 2) if both_views else (1,)
        if not all(visible(sim, c, point) and in_image(sim, c, point, margin) for c in cameras):
            return SurfaceDraw(
                asked, 0, {}, (),
                failure=f"listed markerless target {t.name}: camera "
                f"{' or '.join(map(str, cameras))}'s start image does not show it {margin:g} px "
                "inside (a click and the first look need it)",
            )  # fmt: skip
        listed.append(placed)
    if not spec.count:
        return SurfaceDraw(asked, 0, {}, tuple(listed), listed=len(listed))
    rng = np.random.default_rng([seed, STREAM_SURFACE_TARGETS])
    try:
        found = draw_targets(
            sim,
            spec.count,
            rng,
            spec.depth_m,
            spec.lateral,
            spec.vertical,
            margin_px=margin,
            margin2_px=margin if both_views else None,
        )
    except ValueError as error:
        return SurfaceDraw(
            asked, 0, {}, tuple(listed), failure=f"markerless targets: {error}", listed=len(listed)
        )
    return SurfaceDraw(
        asked, found.drawn, found.refused, (*listed, *found.targets), listed=len(listed)
    )


__all__ = [
    "MARKER_OFFSET_M",
    "TWIN_MARKER",
    "LandingLog",
    "Look",
    "false_fixation_limit_m",
    "measure_surface_targets",
    "row_band_for",
    "score_fixation",
]
