"""Markerless targets on the room's surfaces, as the runner measures them (``[scene.room]
targets``): drawn at the start pose from the seed, told to the head by a click in camera
1's image, fixated through a :class:`~headsim.active.markerless.MarkerlessPair`, and
scored by where each eye's goal ray truly landed.

The head is given only the click, the images and its belief: the pair's band along
camera 1's row of the point +- ``band_px`` in camera 2, from the believed reference
rows (a head that knows no focal length).  The truth (the drawn point, the click's true
projection, the landings) is for placing, the click and scoring only.

A fixation is **false** when the measurement says ok but eye 1's goal ray landed more
than :func:`false_fixation_limit_m` (1 % of the target's depth, at least 5 mm) from the
intended target, or on nothing: a confident wrong correspondence, counted, not hidden.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TypeVar

import numpy as np

from headsim.active.events import Detected, PhaseStarted
from headsim.active.markerless import MarkerlessPair
from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.run.context import PARKED_WORLD_M, record_measurement, simulator
from headsim.run.events import Hub, Stamp
from headsim.run.landing import Landing, fixation_error, landing, vergence_error_deg
from headsim.run.outcomes import (
    FALSE_FIXATION_FRACTION,
    FALSE_FIXATION_MIN_M,
    FixationScore,
    MeasurementRecord,
    SurfaceDraw,
    fixation_stats,
)
from headsim.scenario.spec import (
    MARKER_BODIES,
    STREAM_CLICKS,
    STREAM_SURFACE_TARGETS,
    Scenario,
    SurfaceTargetsSpec,
)
from headsim.scenario.surface_targets import Click, SurfaceTarget, click, draw_targets, point_world
from headsim.sim.simulator import HeadSim
from headsim.vision.correspondence import Band, Match, MatchConfig, row_band


def false_fixation_limit_m(depth_m: float) -> float:
    """How far eye 1's landed point may lie from the target before the fixation is false, m."""
    return max(FALSE_FIXATION_FRACTION * depth_m, FALSE_FIXATION_MIN_M)


class LandingLog:
    """A run subscriber (truth, for scoring): at each look that found the target, that
    camera's goal ray (its goal column ``goal_u``, on the row the look saw the target) at
    the camera's true pose then, cast into the scene, kept with the encoder readings of
    that pose.  The servos are not touched: they report their looks as events."""

    def __init__(self, sim: HeadSim, goal_u: tuple[float, float]) -> None:
        self.sim = sim
        self.goal_u = goal_u
        self.looks: list[tuple[int, tuple[int, ...], Landing]] = []

    def clear(self) -> None:
        self.looks = []

    def encoders(self) -> tuple[int, ...]:
        """Every motor's encoder reading now, whole steps, in ``sim.motors`` order."""
        return tuple(self.sim.encoder_steps(motor) for motor in self.sim.motors)

    def notify(self, event: object, at: Stamp) -> None:
        if isinstance(event, Detected) and event.uv_px is not None:
            goal = (self.goal_u[event.camera - 1], event.uv_px[1])
            self.looks.append(
                (event.camera, self.encoders(), landing(self.sim, event.camera, goal))
            )

    def last(self, camera: int, where: Callable[[tuple[int, ...]], bool]) -> Landing | None:
        """``camera``'s last landing at a pose whose encoders satisfy ``where``."""
        for seen, encoders, landed in reversed(self.looks):
            if seen == camera and where(encoders):
                return landed
        return None

    def fixations(self, m: Measurement) -> dict[int, Landing]:
        """Each camera's landing where its servo left it fixated: Model 2's camera 1 at step
        1's eye encoder, camera 2 at step 2's; Model 1's both at the final pose; the
        one-step fixation's each at its own eye motor's and the neck's final encoders."""
        out: dict[int, Landing] = {}
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

    def _per_eye(self, now: tuple[int, ...]) -> dict[int, Landing]:
        """Each camera's last landing with the neck and that camera's eye motor (camera
        1: ``eye``, camera 2: ``eye2``) at their encoders ``now``."""
        motors = self.sim.motors
        out: dict[int, Landing] = {}
        for camera, eye in ((1, "eye"), (2, "eye2")):
            kept = [k for k, name in enumerate(motors) if name.startswith("neck") or name == eye]

            def same(encoders: tuple[int, ...], kept: list[int] = kept) -> bool:
                return all(encoders[k] == now[k] for k in kept)

            found = self.last(camera, same)
            if found is not None:
                out[camera] = found
        return out


def score_fixation(
    landings: dict[int, Landing],
    target_world_m: np.ndarray,
    depth_m: float,
    ok: bool,
    told: Click,
    match: Match | None,
) -> FixationScore:
    """A :class:`FixationScore` from the logged landings (an eye missing: NaN) and camera
    2's last correspondence ``match``."""
    one, two = landings.get(1), landings.get(2)
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
    off = errors[0][1]
    false = ok and (math.isnan(off) or off > limit)

    def point(x: Landing | None) -> tuple[float, ...] | None:
        return None if x is None or x.point_world_m is None else tuple(map(float, x.point_world_m))

    return FixationScore(
        vergence_error_deg=vergence,
        error_deg=(errors[0][0], errors[1][0]),
        error_m=(errors[0][1], errors[1][1]),
        landed=("" if one is None else one.body, "" if two is None else two.body),
        landed_world_m=(point(one), point(two)),
        click_error_px=math.dist(told.clicked_uv, told.true_uv),
        match_score=None if match is None else float(match.score),
        match_ambiguity=None if match is None else float(match.ambiguity),
        match_status=None if match is None else match.status.value,
        false_fixation=bool(false),
        false_fixation_limit_m=limit,
    )


def row_band_for(
    knowledge: HeadKnowledge, sim: HeadSim, band_px: float
) -> Callable[[tuple[float, float]], Callable[[], Band]]:
    """The band camera 2 searches for camera 1's point at (u, v): camera 1's row shifted
    by the believed reference rows' difference, +- ``band_px``, across camera 2's width
    (the head's belief only; the image size is the image's)."""
    v_shift = knowledge.reference(sim, 2)[1] - knowledge.reference(sim, 1)[1]
    width = sim.camera_settings(2).width

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
    servo: Callable[[HeadSim], S],
    measure: Callable[[HeadSim, S, Target, HeadKnowledge], Measurement],
    both_views: bool = False,
) -> tuple[list[MeasurementRecord], SurfaceDraw]:
    """Each of ``[scene.room] targets`` measured in turn from the start pose: drawn, clicked
    in camera 1's image there, measured with ``measure`` through one shared ``servo``, its
    fixation scored from the looks the run reported (:class:`LandingLog`).
    ``both_views``: draw only points that camera 2's start image also shows with a
    template's room (a servo whose first look is with both cameras: Model 1, the
    one-step fixation); else camera 2 need only see them."""
    spec = scenario.scene.surface_targets
    assert spec is not None
    records: list[MeasurementRecord] = []
    with simulator(hub, "default", scenario) as sim:
        for body in MARKER_BODIES:  # markers play no part: out of every view
            sim.set_body_pose(body, np.array(PARKED_WORLD_M))
        drawn = _draw(sim, spec, scenario.seed, both_views)
        truth = {t.name: np.array(t.point_world_m) for t in drawn.targets}
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        goal_u = (knowledge.reference(sim, 1)[0], knowledge.reference(sim, 2)[0])
        log = LandingLog(sim, goal_u)
        hub.subscribers.append(log)
        try:
            shared = servo(sim)
            clicks = np.random.default_rng([scenario.seed, STREAM_CLICKS])
            band_for = row_band_for(knowledge, sim, spec.band_px)
            for placed in drawn.targets:
                step = hub.begin(placed.name)
                _start_pose(sim)
                first = sim.render(1)
                told = click(sim, np.array(placed.point_world_m), clicks, spec.click_error_px)
                pair = MarkerlessPair(first, told.clicked_uv, band_for)
                target = Target(placed.name, pair, _truth(placed))
                # Depth at the start pose (a failure leaves the head wherever it gave up).
                where = point_world(sim, placed.body, placed.point_body_m)
                truth_head = sim.transform_points(where, "world", "head")[0]
                depth = float(truth_head[2])
                log.clear()
                m = measure(sim, shared, target, knowledge)
                if not m.ok:
                    m = replace(m, truth_head_m=truth_head)
                landings = log.fixations(m)
                # The correspondence the measurement used: camera 2's last confident match
                # (else its last one, whatever it said).
                used = [x for x in pair.finder.matches if x.ok] or pair.finder.matches
                match = used[-1] if used else None
                score = score_fixation(landings, where, depth, m.ok, told, match)
                records.append(record_measurement(hub, m, label, step, fixation=score))
        finally:
            hub.subscribers.remove(log)
    return records, replace(drawn, stats=fixation_stats(records))


def _truth(placed: SurfaceTarget) -> Callable[[HeadSim], np.ndarray]:
    return lambda sim: point_world(sim, placed.body, placed.point_body_m)


def _draw(sim: HeadSim, spec: SurfaceTargetsSpec, seed: int, both_views: bool) -> SurfaceDraw:
    """The targets drawn at the start pose (``both_views``: inside camera 2's image with
    the same margin as camera 1's); none, with the failure, when the surfaces in view
    offer too few (a room and a field that do not meet)."""
    rng = np.random.default_rng([seed, STREAM_SURFACE_TARGETS])
    # Room for camera 1's template around the click, wherever the click error puts it.
    margin = MatchConfig().half_px + 2 + 4 * spec.click_error_px
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
        return SurfaceDraw(spec.count, 0, {}, (), failure=f"markerless targets: {error}")
    return SurfaceDraw(spec.count, found.drawn, found.refused, found.targets)


def fixation_scores(records: Sequence[MeasurementRecord]) -> list[FixationScore]:
    """The records' fixation scores (markerless targets only)."""
    return [r.fixation for r in records if r.fixation is not None]


__all__ = [
    "LandingLog",
    "false_fixation_limit_m",
    "fixation_scores",
    "measure_surface_targets",
    "row_band_for",
    "score_fixation",
]
