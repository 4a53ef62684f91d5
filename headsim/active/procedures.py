"""The paper's measurement procedures run in the simulator, scored against ground truth.

Each procedure drives the head with its own cameras (the image-only servo of
``headsim.active.servo``), feeds encoder readings and pixel coordinates to the pure
estimators of ``headsim.estimators``, and returns a frozen result holding the
estimate, its first-order covariance, the simulator's truth and the error.
Nothing here reads an intrinsic parameter: what the head may know about itself
is a :class:`HeadKnowledge` (initial directions, and optionally vertical
references and kx/ky ratios from the extended calibration).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from headsim.active.events import CalibrationPosition, FixationStarted, MeasurementDone
from headsim.active.search import (
    Failure,
    FailureCause,
    detection_failure,
    find_neck_view,
    find_view,
    nearest_seen,
    neck_failure,
    servo_failure,
)
from headsim.active.servo import Detector, EyeServo, NeckServo, ServoOutcome, ServoResult
from headsim.estimators import PositionEstimate, Uncertainty, model1, model2
from headsim.estimators.areas import (
    AreaComparison,
    areas_from_geometry,
    areas_from_pixels,
    compare_areas,
)
from headsim.estimators.calibration import (
    Calibration,
    LineOfSightCalibration,
    calibrate_initial_directions,
    calibrate_lines_of_sight,
)
from headsim.estimators.result import Method, Status
from headsim.estimators.vertical import VerticalCalibration, calibrate_vertical_reference
from headsim.geometry.kinematics import head_to_world
from headsim.sim import names
from headsim.sim.events import EventSink
from headsim.sim.settings import HeadBelief
from headsim.sim.simulator import HeadSim
from headsim.vision.detect import (
    ChessboardDetection,
    Detection,
    DetectionStatus,
    find_chessboard,
    find_markers,
)

#: Centroid precision assumed for covariances, px (measured: ~0.03-0.06 px).
NOMINAL_PIXEL_SIGMA = 0.05


@dataclass(frozen=True)
class HeadKnowledge:
    """What the head knows about itself; no focal length, no principal point's u.

    ``alpha_e``: each eye's initial direction, rad (0 until calibrated).
    ``v0``: each camera's vertical reference row, px (None: the image centre
    row, the paper's Table VI condition; the principal point's v is Table V).
    ``kx_over_ky``: each camera's pixel aspect ratio (1 unless calibrated).
    ``u0``: each camera's goal column for the servo, px (None: the image
    centre's; e.g. the principal point's column found from a zoom,
    ``headsim.active.principal``).  The initial directions belong to these columns.
    ``belief``: the head's own geometry (baseline, neck D-H, optical-centre
    offsets; None: the simulator's ``belief``, its design, never its truth).
    ``los_offset_m``: how far each goal column's line of sight misses its
    eye's yaw axis, m, along the camera's x (None: the belief's side offsets,
    until the extended calibration measures them).
    """

    alpha_e: tuple[float, float] = (0.0, 0.0)
    v0: tuple[float | None, float | None] = (None, None)
    kx_over_ky: tuple[float, float] = (1.0, 1.0)
    u0: tuple[float | None, float | None] = (None, None)
    belief: HeadBelief | None = None
    los_offset_m: tuple[float, float] | None = None

    def head_belief(self, sim: HeadSim) -> HeadBelief:
        """The geometry the head believes it has."""
        return self.belief if self.belief is not None else sim.belief

    def line_of_sight_offsets(self, sim: HeadSim) -> tuple[float, float]:
        """(s1, s2), m: calibrated, else the believed side offsets."""
        if self.los_offset_m is not None:
            return self.los_offset_m
        return self.head_belief(sim).side_offset_m

    def reference(self, sim: HeadSim, camera: int) -> tuple[float, float]:
        """(u_i0, v_i0): the servo's goal column and the reference row of camera 1 or 2, px."""
        u_c, v_c = sim.camera_settings(camera).image_centre
        u0, v0 = self.u0[camera - 1], self.v0[camera - 1]
        return (u_c if u0 is None else u0, v_c if v0 is None else v0)


@dataclass(frozen=True)
class Target:
    """Something to measure: a name, how to find it in an image, and where it truly is."""

    name: str
    detector: Detector
    truth_world: Callable[[HeadSim], np.ndarray]


def body_target(name: str, detector: Detector) -> Target:
    """A target whose true position is a body's origin (markers, the block cross point)."""
    return Target(name, detector, lambda sim: sim.position(name))


@dataclass(frozen=True)
class Measurement:
    """One measured point: estimate and truth in H and W, m; covariance in H, m^2.

    ``status``: :attr:`Status.OK` or :attr:`Status.FAILED`; ``detail``: why it
    failed (``failure.message``), "" when ok; ``status_text``: results.json's "status".
    ``renders``: images this measurement took, ``search_renders`` of them
    spent finding a lost target again.  ``servo_residual_px``: the final
    |u - u_i0| of each servo.  ``details``: angles and pixels used.
    ``failure``: the cause, None when ok.
    """

    name: str
    method: Method
    status: Status
    estimate_head_m: np.ndarray
    truth_head_m: np.ndarray
    estimate_world_m: np.ndarray
    truth_world_m: np.ndarray
    covariance_head_m2: np.ndarray
    renders: int
    servo_residual_px: tuple[float, ...]
    details: dict[str, float] = field(default_factory=dict)
    failure: Failure | None = None
    search_renders: int = 0
    detail: str = ""

    @property
    def ok(self) -> bool:
        return self.status is Status.OK

    @property
    def status_text(self) -> str:
        """ "ok", or why it failed."""
        return "ok" if self.ok else self.detail

    @property
    def error_head_m(self) -> np.ndarray:
        """Estimate minus truth in H, m."""
        return self.estimate_head_m - self.truth_head_m

    @property
    def depth_m(self) -> float:
        """True depth z_h, m."""
        return float(self.truth_head_m[2])

    @property
    def error_pct_of_depth(self) -> float:
        """3-D error as a percentage of the true depth."""
        return float(100.0 * np.linalg.norm(self.error_head_m) / self.depth_m)


def _nan3() -> np.ndarray:
    return np.full(3, np.nan)


def _failed(
    sim: HeadSim,
    target: Target,
    method: str,
    failure: Failure,
    renders: int,
    residuals: Sequence[float],
    search_renders: int = 0,
) -> Measurement:
    truth_world = target.truth_world(sim)
    return Measurement(
        name=target.name,
        method=Method(method),
        status=Status.FAILED,
        detail=failure.message,
        failure=failure,
        search_renders=search_renders,
        estimate_head_m=_nan3(),
        truth_head_m=sim.transform_points(truth_world, "world", "head")[0],
        estimate_world_m=_nan3(),
        truth_world_m=truth_world,
        covariance_head_m2=np.full((3, 3), np.nan),
        renders=renders,
        servo_residual_px=tuple(residuals),
    )


def _observe(servo: EyeServo, camera: int, target: Target) -> Detection:
    return servo.observe(camera, target.detector)


def _fixation_angle(sim: HeadSim, result: ServoResult, interpolate: bool) -> float:
    """Eye angle at fixation, rad: the whole step, or the sub-step interpolated from the image."""
    steps = result.subpixel_steps if interpolate else float(result.steps)
    return steps * sim.settings.encoder_resolution_rad


@dataclass(frozen=True)
class Model2Config:
    """Options of the two-step measurement.

    ``interpolate``: use the servo's sub-step fixation (image residual / gain)
    instead of the whole encoder step.  ``midline_px``: when P's offset from
    the goal column in a y image is below this, take that image again at an
    eye angle ``remedy_px`` of image motion away (the paper's near-midline
    remedy, generalised from gamma = 0 to any gamma).
    """

    interpolate: bool = True
    midline_px: float = 25.0
    remedy_px: float = 120.0


def measure_model2(
    sim: HeadSim,
    servo: EyeServo,
    target: Target,
    knowledge: HeadKnowledge | None = None,
    config: Model2Config | None = None,
) -> Measurement:
    """Model 2, the two-step measurement of Sec. II-C, with the neck still."""
    knowledge = knowledge or HeadKnowledge()
    config = config or Model2Config()
    resolution = sim.settings.encoder_resolution_rad
    start = sim.render_count
    (u10, v10), (u20, v20) = knowledge.reference(sim, 1), knowledge.reference(sim, 2)
    # Step 1: Ca1's u to its goal column; then P's image in Ca2 there.
    step1 = servo.run(1, target.detector, goal_u=u10)
    search = 0  # renders spent finding the target again
    if step1.outcome is ServoOutcome.TARGET_LOST and step1.iterations == 0:
        # Not in Ca1's view where the last measurement left the eyes: search.
        before = sim.render_count
        found = find_view(servo, 1, target.detector)
        search += sim.render_count - before
        if found is not None:
            step1 = servo.run(1, target.detector, goal_u=u10, first=found.detection)
    if not step1.converged:
        failure = servo_failure(step1, "step 1", 1)
        if search:
            failure = replace(failure, detail=f"{failure.detail}; searched {search} poses")
        return _failed(
            sim,
            target,
            "model2",
            failure,
            sim.render_count - start,
            [step1.residual_px],
            search,
        )
    seen2 = _observe(servo, 2, target)
    gamma2_steps = step1.steps
    if not seen2.found or seen2.uv is None:
        # Ca2 does not see P where Ca1 fixates it (a lateral target, a long focal
        # length): its y image is taken at an intermediate eye angle where it does,
        # and step 2 starts there.
        before = sim.render_count
        found = find_view(servo, 2, target.detector)
        search += sim.render_count - before
        if found is None:
            failure = detection_failure(seen2, "step 1", 2, f"and at {search} eye angles searched")
            return _failed(
                sim,
                target,
                "model2",
                failure,
                sim.render_count - start,
                [step1.residual_px],
                search,
            )
        seen2, gamma2_steps = found.detection, found.steps
    # Step 2: Ca2's u to its goal column, starting from that image; then Ca1's image.
    step2 = servo.run(2, target.detector, goal_u=u20, first=seen2)
    residuals = (step1.residual_px, step2.residual_px)
    if not step2.converged:
        return _failed(
            sim,
            target,
            "model2",
            servo_failure(step2, "step 2", 2),
            sim.render_count - start,
            residuals,
            search,
        )
    seen1 = _observe(servo, 1, target)
    gamma1_steps = step2.steps
    uv1_seen = seen1.uv if seen1.found else None
    if uv1_seen is None:
        # Ca1 does not see P where Ca2 fixates it: its y image is one step 1 took.
        memory = nearest_seen(step1.seen, step2.steps, u10, config.midline_px)
        if memory is None:
            return _failed(
                sim,
                target,
                "model2",
                detection_failure(seen1, "step 2", 1),
                sim.render_count - start,
                residuals,
                search,
            )
        gamma1_steps, uv1_seen = memory[0], (memory[1], memory[2])
    assert seen2.uv is not None

    uv1, uv2 = np.array(uv1_seen), np.array(seen2.uv)
    gamma1, gamma2 = gamma1_steps * resolution, gamma2_steps * resolution
    if min(abs(uv1[0] - u10), abs(uv2[0] - u20)) < config.midline_px:
        remedy = _near_midline_images(sim, servo, target, step1, step2, config)
        if remedy is not None:
            gamma, r1, r2 = remedy
            if r1 is not None and abs(r1[0] - u10) > abs(uv1[0] - u10):
                uv1, gamma1 = r1, gamma
            if r2 is not None and abs(r2[0] - u20) > abs(uv2[0] - u20):
                uv2, gamma2 = r2, gamma

    alpha1 = _fixation_angle(sim, step1, config.interpolate)
    alpha2 = _fixation_angle(sim, step2, config.interpolate)
    gains = [abs(r.gain_px_per_step or 1.0) for r in (step1, step2)]
    angle_sigma = (
        resolution * NOMINAL_PIXEL_SIGMA / min(gains)
        if config.interpolate
        else resolution / math.sqrt(12.0)
    )
    estimate = model2(
        [alpha1],
        [alpha2],
        uv1[None],
        uv2[None],
        knowledge.head_belief(sim).baseline_m,
        uv10=(u10, v10),
        uv20=(u20, v20),
        alpha_e=knowledge.alpha_e,
        gamma1=[gamma1],
        gamma2=[gamma2],
        kx_over_ky=knowledge.kx_over_ky,
        uncertainty=Uncertainty(encoder=angle_sigma, pixel=NOMINAL_PIXEL_SIGMA),
        los_offset_m=knowledge.line_of_sight_offsets(sim),
    )
    details = {
        "alpha1_rad": alpha1,
        "alpha2_rad": alpha2,
        "step1_encoder_rad": step1.steps * resolution,
        "step2_encoder_rad": step2.steps * resolution,
        "gamma1_rad": gamma1,
        "gamma2_rad": gamma2,
        "u11_px": float(uv1[0]),
        "v11_px": float(uv1[1]),
        "u21_px": float(uv2[0]),
        "v21_px": float(uv2[1]),
    }
    return _measured(
        sim,
        target,
        "model2",
        estimate,
        start,
        residuals,
        details,
        belief=knowledge.head_belief(sim),
        search=search,
    )


def _measured(
    sim: HeadSim,
    target: Target,
    method: str,
    estimate: PositionEstimate,
    start: int,
    residuals: tuple[float, ...],
    details: dict[str, float],
    neck_rad: tuple[float, float] | None = None,
    belief: HeadBelief | None = None,
    search: int = 0,
) -> Measurement:
    """The measurement of one estimated point (or why it is invalid) beside the truth."""
    renders = sim.render_count - start
    if not bool(estimate.valid[0]):
        failure = Failure(FailureCause.ESTIMATOR, "estimate", None, repr(estimate.reasons(0)))
        return _failed(sim, target, method, failure, renders, residuals, search)
    truth_world = target.truth_world(sim)
    estimate_head = estimate.positions[0]
    covariance = estimate.covariance
    return Measurement(
        name=target.name,
        method=Method(method),
        status=Status.OK,
        estimate_head_m=estimate_head,
        truth_head_m=sim.transform_points(truth_world, "world", "head")[0],
        estimate_world_m=to_world(sim, estimate_head, neck_rad, belief),
        truth_world_m=truth_world,
        covariance_head_m2=covariance[0] if covariance is not None else np.full((3, 3), np.nan),
        renders=renders,
        servo_residual_px=residuals,
        details=details,
        search_renders=search,
    )


def _near_midline_images(
    sim: HeadSim,
    servo: EyeServo,
    target: Target,
    step1: ServoResult,
    step2: ServoResult,
    config: Model2Config,
) -> tuple[float, np.ndarray | None, np.ndarray | None] | None:
    """Both cameras' images at an eye angle ``remedy_px`` of image motion off the fixations."""
    gain = max(abs(step1.gain_px_per_step or 0.0), abs(step2.gain_px_per_step or 0.0))
    if gain == 0.0:
        return None
    offset = round(config.remedy_px / gain)
    low, high = servo.step_range
    middle = (step1.steps + step2.steps) / 2
    # Turn outward (towards 0) when converged far in, else inward: stay within range.
    gamma_steps = round(middle - offset) if middle - offset >= low else round(middle + offset)
    if not low <= gamma_steps <= high:
        return None
    sim.command_eye_steps(gamma_steps)
    sim.settle()
    seen = [_observe(servo, camera, target) for camera in (1, 2)]
    uv = [np.array(s.uv) if s.found and s.uv is not None else None for s in seen]
    return gamma_steps * sim.settings.encoder_resolution_rad, uv[0], uv[1]


# -- Calibration of the initial directions (Sec. V) ----------------------


class CalibrationError(ValueError):
    """The calibration failed; the message names the cause, ``outcomes`` has each position's."""

    def __init__(self, message: str, outcomes: Sequence[Failure | None]) -> None:
        super().__init__(message)
        self.outcomes = tuple(outcomes)


def _causes_text(outcomes: Sequence[Failure | None]) -> str:
    """'3 Ca2 at step 1: target lost, 1 Ca1 at step 1: target cut' (most common first)."""
    counts: dict[str, int] = {}
    for f in outcomes:
        if f is not None:
            key = f.message.split(" (")[0]
            counts[key] = counts.get(key, 0) + 1
    return ", ".join(f"{n} {k}" for k, n in sorted(counts.items(), key=lambda kv: -kv[1]))


@dataclass(frozen=True)
class CalibrationRun:
    """Sec. V calibration in the simulator, with the truth beside it.

    ``fit``: the estimator's result (offsets, standard errors, residuals).
    ``truth_alpha_e``: each eye's effective initial direction, rad (simulator).
    ``vertical``: the extended calibration per camera (v0, kx/ky), or None.
    ``lines``: the extended fit of each eye's initial direction and
    line-of-sight offset from the targets' measured positions, or None.
    ``outcomes``: per layout position, None (fixated) or why it was not.
    """

    fit: Calibration
    truth_alpha_e: tuple[float, float]
    samples: int
    renders: int
    depth_noise_m: float
    vertical: tuple[VerticalCalibration, VerticalCalibration] | None
    knowledge: HeadKnowledge
    lines: LineOfSightCalibration | None = None
    position_noise_m: float = 0.0
    outcomes: tuple[Failure | None, ...] = ()

    @property
    def alpha_e_error(self) -> np.ndarray:
        """Calibrated minus true effective initial directions, rad."""
        return np.asarray(self.fit.alpha_e) - np.asarray(self.truth_alpha_e)


def calibration_layout(
    sim: HeadSim,
    rng: np.random.Generator,
    count: int = 60,
    depth_range_m: tuple[float, float] = (0.25, 0.6),
    lateral: float = 0.16,
    vertical: float = 0.08,
    radius_m: float = 0.008,
    depths_m: np.ndarray | None = None,
    eye_angles_rad: Sequence[float] = (),
) -> np.ndarray:
    """World positions (count, 3) for Sec. V calibration targets, seeded.

    Near targets spread sideways separate the two offsets best (eq. 23 is one
    equation in two unknowns per sample; their sec^2 terms differ most up
    close): 60 targets at 0.25-0.6 m recover them to about 1e-4 rad with the
    paper's cameras.  ``lateral``/``vertical``: x_h/z_h and y_h/z_h spread; a
    vertical spread is what the extended calibration needs.  Every position is
    seen whole (ball of ``radius_m``) by both cameras at the current pose, or
    at one of ``eye_angles_rad`` (encoder angles, neck still): at a long focal
    length the near, lateral positions that separate the offsets are in the
    common view only with the eyes turned in (Model 2 finds them by search;
    the first position is always in view at the current pose).
    ``depths_m``: (count,) each position's depth z_h, m, kept when it is drawn
    again (e.g. :func:`headsim.scenario.calibration_design.near_far_depths`); None:
    uniform in ``depth_range_m``.
    """
    resolution = sim.settings.encoder_resolution_rad
    eye_steps = [round(a / resolution) for a in eye_angles_rad]

    def seen(points: np.ndarray) -> np.ndarray:
        ok = seen_by_both(sim, points, radius_m)
        if eye_steps:
            before = sim.eye_encoder_steps()
            for steps in eye_steps:
                sim.command_eye_steps(steps)
                sim.settle()
                ok |= seen_by_both(sim, points, radius_m)
            sim.command_eye_steps(before)
            sim.settle()
        return ok

    def draw(n: int, slots: np.ndarray | None = None) -> np.ndarray:
        z = rng.uniform(*depth_range_m, size=n) if depths_m is None else depths_m[slots]
        return np.column_stack(
            [rng.uniform(-lateral, lateral, n) * z, rng.uniform(-vertical, vertical, n) * z, z]
        )

    if depths_m is not None:
        depths_m = np.asarray(depths_m, dtype=float)
        if depths_m.shape != (count,):
            raise ValueError(f"depths_m must have shape ({count},), got {depths_m.shape}")
    points_world = sim.transform_points(draw(count, np.arange(count)), "head", "world")
    # Placement (truth allowed): keep positions both cameras see whole from where the
    # head stands; a position that one cannot see is drawn again, a bounded number of times.
    for _ in range(500):
        unseen = ~seen(points_world)
        # The first position in view from where the head stands: the servo learns
        # its gains there, which the search for the others needs.
        unseen[0] |= not seen_by_both(sim, points_world[:1], radius_m)[0]
        if not unseen.any():
            return points_world
        points_world[unseen] = sim.transform_points(
            draw(int(unseen.sum()), np.flatnonzero(unseen)), "head", "world"
        )
    raise ValueError(
        f"calibration layout: {int(unseen.sum())} of {count} positions stay outside a camera's "
        f"view after 500 draws: depth {depth_range_m} m, lateral {lateral}, vertical {vertical} "
        "reach outside the field both cameras share at this focal length"
    )


def seen_by_both(sim: HeadSim, points_world: np.ndarray, radius_m: float = 0.0) -> np.ndarray:
    """(N,) whether each world point images whole inside both cameras at the current pose.

    Placement and checks only (it uses the true intrinsics): the point's image,
    plus its apparent radius and 2 px, lies inside the image.
    """
    points_world = np.atleast_2d(points_world)
    ok = np.ones(len(points_world), dtype=bool)
    for camera in (1, 2):
        cam = sim.camera_settings(camera)
        uv = sim.project(points_world, camera)
        depth = sim.transform_points(points_world, "world", names.CAMERAS[camera - 1])[:, 2]
        margin = 2.0 + max(cam.kx, cam.ky) * radius_m / np.maximum(depth, 1e-9)
        with np.errstate(invalid="ignore"):
            ok &= (
                (depth > 0)
                & (uv[:, 0] >= margin)
                & (uv[:, 0] <= cam.width - 1 - margin)
                & (uv[:, 1] >= margin)
                & (uv[:, 1] <= cam.height - 1 - margin)
            )
    return ok


def calibrate_head(
    sim: HeadSim,
    servo: EyeServo,
    target: Target,
    body: str,
    positions_world: np.ndarray,
    *,
    depth_noise_m: float = 0.0,
    rng: np.random.Generator | None = None,
    extended: bool = True,
    knowledge: HeadKnowledge | None = None,
    position_noise_m: float = 0.0,
    lines_of_sight: bool = False,
    sink: EventSink | None = None,
) -> CalibrationRun:
    """Fixate ``target`` (moved with body ``body``) at each position and calibrate.

    The depth z_h handed to the estimator is the true one plus Gaussian noise of
    ``depth_noise_m`` (a tape measure).  With ``extended``, the same samples
    also give each camera's vertical reference and kx/ky ratio (beyond the
    paper: it needs the targets' full known positions, not only their depth).
    ``knowledge``: what the head already knows; its goal columns ``u0`` are
    the ones the servo fixates on (default: the image centres).
    ``position_noise_m``: Gaussian error of every coordinate a user measures
    of each target (x_h, y_h, z_h from the head's frame: a tape measure), m;
    the depth noise adds to it on z_h.  Every fit takes the measured values.
    With ``extended``, ``lines_of_sight`` and at least 3 targets, each eye's
    initial direction and line-of-sight offset are fitted jointly from the measured positions
    (:func:`calibrate_lines_of_sight`) and replace Sec. V's directions, unless
    the layout cannot separate them (``lines.separable`` False, with its message).
    ``sink``: where each position's fixation is reported ("calibration 1", ...; None:
    the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    base = replace(knowledge or HeadKnowledge(), alpha_e=(0.0, 0.0), los_offset_m=None)
    rng = rng or np.random.default_rng(0)
    start = sim.render_count
    parked = sim.position(body)  # put the target back afterwards: it must not hide others
    alpha1, alpha2, depths, rows = [], [], [], []
    outcomes: list[Failure | None] = []
    plain = Model2Config(midline_px=0.0)
    for index, position in enumerate(np.atleast_2d(positions_world)):
        sink.emit(FixationStarted(f"calibration {index + 1}"))
        sim.set_body_pose(body, position)
        m = measure_model2(sim, servo, target, base, plain)
        if m.failure is not None and m.failure.cause is FailureCause.ESTIMATOR:
            # Near the midline the y images hold almost no x offset (NO_Y): take
            # them again at an intermediate eye angle, the near-midline remedy.
            m = measure_model2(sim, servo, target, base, Model2Config())
        sink.emit(CalibrationPosition(index, position, m))
        outcomes.append(m.failure)
        if not m.ok:
            continue
        alpha1.append(m.details["alpha1_rad"])
        alpha2.append(m.details["alpha2_rad"])
        measured = m.truth_head_m.copy()
        if position_noise_m > 0:
            measured = measured + rng.normal(0.0, position_noise_m, 3)
        if depth_noise_m > 0:
            measured[2] += rng.normal(0.0, depth_noise_m)
        depths.append(measured[2])
        rows.append((measured, m.details))
    sim.park_body(body, parked)
    baseline = base.head_belief(sim).baseline_m
    total = len(outcomes)
    if len(alpha1) < 2:
        raise CalibrationError(
            f"too few positions seen: {len(alpha1)} of {total} fixated (at least 2 needed) "
            f"because {_causes_text(outcomes)}",
            outcomes,
        )
    measured_rows = np.array([r[0] for r in rows])
    ratios = measured_rows[:, 0] / measured_rows[:, 2]
    # Without a depth error model the fit is unweighted and its standard errors
    # come from the scatter of its residuals (the angles' noise is not known a priori).
    z_sigma = math.hypot(depth_noise_m, position_noise_m)
    try:
        fit = calibrate_initial_directions(
            np.array(alpha1),
            np.array(alpha2),
            np.array(depths),
            baseline,
            sigma_encoder=sim.settings.encoder_resolution_rad * 0.25 if z_sigma > 0 else None,
            sigma_depth=z_sigma if z_sigma > 0 else None,
        )
    except ValueError as err:
        raise CalibrationError(
            f"degenerate layout because the {len(alpha1)} fixated positions span depths "
            f"{measured_rows[:, 2].min():.3f}-{measured_rows[:, 2].max():.3f} m and x/z "
            f"{ratios.min():+.3f} to {ratios.max():+.3f}, which do not separate the two "
            f"initial directions ({err})",
            outcomes,
        ) from err
    alpha_e = (float(fit.alpha_e[0]), float(fit.alpha_e[1]))
    calibrated = replace(base, alpha_e=alpha_e)
    vertical = None
    lines = None
    offsets = base.head_belief(sim).side_offset_m
    if extended and lines_of_sight and len(rows) >= 3:
        # Off by default: on a head whose centres are on their axes the two
        # extra unknowns only add their calibration noise (about 0.01 % of depth).
        positions = np.array([r[0] for r in rows])
        lines = calibrate_lines_of_sight(
            np.array(alpha1),
            np.array(alpha2),
            positions,
            baseline,
            # A floor of 0.1 mm: the servo's own scatter when the tape is exact.
            sigma_position=max(position_noise_m, depth_noise_m, 1e-4),
            sigma_encoder=sim.settings.encoder_resolution_rad * 0.3,
            initial=alpha_e,
        )
        if lines.separable:
            alpha_e = (float(lines.alpha_e[0]), float(lines.alpha_e[1]))
            offsets = (float(lines.offset_m[0]), float(lines.offset_m[1]))
            calibrated = replace(calibrated, alpha_e=alpha_e, los_offset_m=offsets)
        else:  # the layout cannot tell offsets from directions: keep Sec. V's and the belief's
            calibrated = replace(calibrated, los_offset_m=None)
    if extended and len(rows) >= 3:
        heights = measured_rows[:, 1] / measured_rows[:, 2]
        if np.ptp(heights) < 1e-6:
            raise CalibrationError(
                f"the extended fit (v0, kx/ky) needs a vertical spread, but the "
                f"{len(rows)} fixated positions all have y/z = {heights[0]:+.4f}: set "
                "experiment.calibration.vertical > 0, or extended = false",
                outcomes,
            )
        try:
            vertical = _vertical_from_samples(sim, rows, alpha_e, base, offsets)
        except ValueError as err:
            raise CalibrationError(
                f"degenerate layout for the extended fit because {err}", outcomes
            ) from err
        calibrated = replace(
            calibrated,
            v0=(vertical[0].v0, vertical[1].v0),
            kx_over_ky=(vertical[0].kx_over_ky, vertical[1].kx_over_ky),
        )
    truth = tuple(
        sim.effective_initial_direction(camera, base.reference(sim, camera)[0]) for camera in (1, 2)
    )
    return CalibrationRun(
        fit=fit,
        truth_alpha_e=(truth[0], truth[1]),
        samples=len(alpha1),
        renders=sim.render_count - start,
        depth_noise_m=depth_noise_m,
        vertical=vertical,
        knowledge=calibrated,
        lines=lines,
        position_noise_m=position_noise_m,
        outcomes=tuple(outcomes),
    )


@dataclass(frozen=True)
class LineOfSightTruth:
    """Each goal column's true line-of-sight offset from its *believed* yaw axis, m.

    ``offset_m``: (s1, s2) along each camera's x, at eye angle 0 and the image
    centre row: the optical centre's own offset ``e cos t - n sin t`` plus the
    axis's true-minus-believed position (half the baseline error, outward).
    ``effective_baseline_m``: believed D - s1 + s2 = true D - s1_own + s2_own.
    """

    offset_m: tuple[float, float]
    effective_baseline_m: float


def line_of_sight_truth(sim: HeadSim, knowledge: HeadKnowledge) -> LineOfSightTruth:
    """Ground truth for the extended calibration's offsets (scoring only)."""
    believed = knowledge.head_belief(sim).baseline_m
    half_error = 0.5 * (sim.settings.baseline_m - believed)
    out = []
    for camera, sign in ((1, -1.0), (2, 1.0)):
        cam = sim.camera_settings(camera)
        u0 = knowledge.reference(sim, camera)[0]
        t = float(cam.pinhole().column_angle(u0))
        own = cam.side_offset_m * math.cos(t) - cam.nodal_offset_m * math.sin(t)
        out.append(own + sign * half_error)
    return LineOfSightTruth((out[0], out[1]), believed - out[0] + out[1])


def _vertical_from_samples(
    sim: HeadSim,
    rows: list[tuple[np.ndarray, dict[str, float]]],
    alpha_e: tuple[float, float],
    base: HeadKnowledge,
    offsets: tuple[float, float] = (0.0, 0.0),
) -> tuple[VerticalCalibration, VerticalCalibration]:
    """Fit (v0, kx/ky) per camera from the calibration fixations at measured positions."""
    truth = np.array([r[0] for r in rows])
    d = {key: np.array([r[1][key] for r in rows]) for key in rows[0][1]}
    z = truth[:, 2]
    a1, a2 = d["alpha1_rad"] + alpha_e[0], d["alpha2_rad"] + alpha_e[1]
    s1, s2 = offsets
    # P's x in each camera's effective frame when its y image was taken (eqs. 8, 10,
    # with the line-of-sight offsets as in headsim.estimators.model2).
    rel1 = d["alpha1_rad"] - d["gamma1_rad"]
    rel2 = d["gamma2_rad"] - d["alpha2_rad"]
    x_c1 = (z + s1 * np.sin(a1)) / np.cos(a1) * np.sin(rel1) + s1 * (np.cos(rel1) - 1.0)
    x_c2 = (z - s2 * np.sin(a2)) / np.cos(a2) * np.sin(rel2) + s2 * (np.cos(rel2) - 1.0)
    u10, u20 = base.reference(sim, 1)[0], base.reference(sim, 2)[0]
    cam1 = calibrate_vertical_reference(d["u11_px"] - u10, d["v11_px"], x_c1, truth[:, 1])
    cam2 = calibrate_vertical_reference(d["u21_px"] - u20, d["v21_px"], x_c2, truth[:, 1])
    return cam1, cam2


# -- Model 1: fixation with the neck (Sec. II-B) --------------------------


def measure_points_model2(
    sim: HeadSim,
    servo: EyeServo,
    targets: Sequence[Target],
    knowledge: HeadKnowledge | None = None,
    config: Model2Config | None = None,
) -> list[Measurement]:
    """Model 2 on several targets in turn (the servo's gains carry over)."""
    return [measure_model2(sim, servo, t, knowledge, config) for t in targets]


def to_world(
    sim: HeadSim,
    point_head: np.ndarray,
    neck_rad: tuple[float, float] | None = None,
    belief: HeadBelief | None = None,
) -> np.ndarray:
    """A head-frame estimate in W through eq. (3) with the believed D-H lengths
    (default ``sim.belief``), with the neck encoder readings by default."""
    theta1, theta2 = sim.neck_encoders() if neck_rad is None else neck_rad
    b = belief if belief is not None else sim.belief
    return head_to_world(point_head, theta1, theta2, b.neck_d1_m, b.neck_a2_m)


def measure_model1(
    sim: HeadSim,
    servo: NeckServo,
    target: Target,
    knowledge: HeadKnowledge | None = None,
    interpolate: bool = True,
    last_seen: Sequence[tuple[int, int, int]] = (),
) -> Measurement:
    """Model 1: fixate with neck and eyes, then eqs. (2)-(3) (Sec. II-B).

    ``last_seen``: (yaw, pitch, eye) steps of the last fixations of this same
    target, oldest first (tracking).  If both cameras do not see it where the
    neck was left, the head looks around the last of them (and where the last
    two predict it), then from the start pose; every look is counted in
    ``search_renders``.
    """
    knowledge = knowledge or HeadKnowledge()
    start = sim.render_count
    (u10, v10), (u20, v20) = knowledge.reference(sim, 1), knowledge.reference(sim, 2)
    goals = (u10, u20, (v10 + v20) / 2)
    result = servo.run(target.detector, goals=goals)
    search = 0
    if result.outcome is ServoOutcome.TARGET_LOST and result.iterations == 0:
        search = result.renders  # the look that did not find it
        found = None
        if last_seen:
            # A tracked target left the view: look around its last fixation.
            before = sim.render_count
            found = find_neck_view(servo, target.detector, last_seen)
            search += sim.render_count - before
            if found is not None:
                result = servo.run(target.detector, goals=goals)
        if found is None and any(servo.steps()):
            # Not in both views where the neck was left (the last target's pose),
            # nor around it: back to the start pose and fixate from there.
            sim.command(neck_yaw=0.0, neck_pitch=0.0, eye=0.0)
            sim.settle()
            result = servo.run(target.detector, goals=goals)
        elif found is None:
            search = 0  # nothing else was tried: the first look's failure stands
    residual = (result.residual_px,)
    if not result.converged:
        return _failed(
            sim,
            target,
            "model1",
            neck_failure(result),
            sim.render_count - start,
            residual,
            search,
        )
    resolution = sim.settings.encoder_resolution_rad
    yaw, pitch, eye = (
        s * resolution for s in (result.subpixel_steps if interpolate else result.steps)
    )
    angle_sigma = resolution * (0.3 if interpolate else 1 / math.sqrt(12.0))
    belief = knowledge.head_belief(sim)
    estimate = model1(
        [eye],
        belief.baseline_m,
        alpha_e=knowledge.alpha_e,
        uncertainty=Uncertainty(encoder=angle_sigma),
        los_offset_m=knowledge.line_of_sight_offsets(sim),
    )
    details = {"alpha_rad": eye, "neck_yaw_rad": yaw, "neck_pitch_rad": pitch}
    return _measured(
        sim, target, "model1", estimate, start, residual, details, (yaw, pitch), belief, search
    )


@dataclass(frozen=True)
class TrackingRun:
    """A moving target followed with the neck model: one measurement per fixation, time in s."""

    times_s: np.ndarray
    measurements: tuple[Measurement, ...]

    @property
    def errors_world_m(self) -> np.ndarray:
        """(N,) 3-D error of each fixation in W, m (NaN where it failed)."""
        return np.array(
            [np.linalg.norm(m.estimate_world_m - m.truth_world_m) for m in self.measurements]
        )


def track_moving_target(
    sim: HeadSim,
    servo: NeckServo,
    target: Target,
    body: str,
    trajectory: Callable[[float], np.ndarray],
    times_s: Sequence[float],
    knowledge: HeadKnowledge | None = None,
    sink: EventSink | None = None,
) -> TrackingRun:
    """Move ``body`` along ``trajectory(t)`` (world, m) and fixate it at each time with Model 1.

    The servo's Jacobian carries from one fixation to the next, so after the
    first fixation each one starts from the last and takes few renders.  A
    target that left both views since is searched for around the last
    fixation (:func:`headsim.active.search.find_neck_view`), then from the start pose.
    ``sink``: where each fixation ("<target> 1", ...) and measurement is reported
    (None: the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    measurements = []
    fixations: list[tuple[int, int, int]] = []  # where the target was seen, in steps
    for k, t in enumerate(times_s):
        sink.emit(FixationStarted(f"{target.name} {k + 1}"))
        sim.set_body_pose(body, trajectory(float(t)))
        m = measure_model1(sim, servo, target, knowledge, last_seen=fixations[-2:])
        sink.emit(MeasurementDone(m, float(t)))
        measurements.append(m)
        if m.ok:
            fixations.append(servo.steps())
    return TrackingRun(np.asarray(times_s, dtype=float), tuple(measurements))


# -- Chessboard (Sec. VI-A) ------------------------------------------------


def board_extent(board: ChessboardDetection, index: int) -> tuple[float, float, float, float]:
    """(left, top, right, bottom) px from corner ``index`` of what finding ``board`` needs:
    its inner corners, the outer squares, and half a square of the border around them."""
    corners = board.corners
    assert corners is not None
    columns, rows = board.pattern
    grid = corners.reshape(rows, columns, 2)
    spacing = float(
        max(
            np.linalg.norm(np.diff(grid, axis=1), axis=-1).max(),
            np.linalg.norm(np.diff(grid, axis=0), axis=-1).max(),
        )
    )
    low, high = corners.min(axis=0) - corners[index], corners.max(axis=0) - corners[index]
    pad = 1.5 * spacing
    return (
        float(low[0] - pad),
        float(low[1] - pad),
        float(high[0] + pad),
        float(high[1] + pad),
    )


def chessboard_corner_target(index: int, pattern: tuple[int, int], square_m: float) -> Target:
    """Inner corner ``index`` (row-major from the top-left) of the scene's chessboard.

    Found by detecting the whole board (``find_chessboard``): a board cut by
    the image border loses its corners, it does not guess them.
    """
    columns, _ = pattern
    i, j = index % columns, index // columns

    def detect(image: np.ndarray) -> Detection:
        board = find_chessboard(image, pattern)
        if not board.found:
            return Detection(board.status, None, 0.0)
        u, v = board.corners[index]
        return Detection(
            DetectionStatus.FOUND, (float(u), float(v)), 1.0, board_extent(board, index)
        )

    # Every corner of one board looks for the whole board: they share windows.
    detect.window_key = ("chessboard", pattern, square_m)  # type: ignore[attr-defined]

    def truth(sim: HeadSim) -> np.ndarray:
        body = sim.data.body(names.CHESSBOARD)
        return body.xpos + body.xmat.reshape(3, 3) @ np.array([i * square_m, j * square_m, 0.0])

    return Target(f"corner_{i}_{j}", detect, truth)


@dataclass(frozen=True)
class ChessboardRun:
    """Every cross point measured with Model 2, and the squares' sides they give, m.

    ``widths_m``/``heights_m``: distances between horizontally/vertically
    adjacent measured corners (estimate), with the truth beside them.
    """

    measurements: tuple[Measurement, ...]
    square_m: float
    widths_m: np.ndarray
    heights_m: np.ndarray
    true_widths_m: np.ndarray
    true_heights_m: np.ndarray

    @property
    def measured(self) -> int:
        return sum(m.ok for m in self.measurements)


def measure_chessboard(
    sim: HeadSim,
    servo: EyeServo,
    knowledge: HeadKnowledge | None = None,
    config: Model2Config | None = None,
    pattern: tuple[int, int] = (8, 6),
    square_m: float = 0.030,
    corners: Sequence[int] | None = None,
    sink: EventSink | None = None,
) -> ChessboardRun:
    """Measure the chessboard's cross points (all, or ``corners``) and its squares' sides.

    ``sink``: where each corner's fixation ("corner_i_j") and measurement is
    reported (None: the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    columns, rows = pattern
    indices = list(range(columns * rows)) if corners is None else list(corners)
    measured: dict[int, Measurement] = {}
    for k in indices:
        corner = chessboard_corner_target(k, pattern, square_m)
        sink.emit(FixationStarted(corner.name))
        measured[k] = measure_model2(sim, servo, corner, knowledge, config)
        sink.emit(MeasurementDone(measured[k]))
    widths, heights, true_widths, true_heights = [], [], [], []
    for k, m in measured.items():
        for neighbour, out, out_true in (
            (k + 1, widths, true_widths),
            (k + columns, heights, true_heights),
        ):
            if neighbour == k + 1 and (k + 1) % columns == 0:
                continue
            other = measured.get(neighbour)
            if other is None or not (m.ok and other.ok):
                continue
            out.append(float(np.linalg.norm(other.estimate_head_m - m.estimate_head_m)))
            out_true.append(float(np.linalg.norm(other.truth_head_m - m.truth_head_m)))
    return ChessboardRun(
        measurements=tuple(measured.values()),
        square_m=square_m,
        widths_m=np.array(widths),
        heights_m=np.array(heights),
        true_widths_m=np.array(true_widths),
        true_heights_m=np.array(true_heights),
    )


# -- Relative positioning of several objects (Sec. III) --------------------


@dataclass(frozen=True)
class RelativeRun:
    """Areas S1..S12 of objects around a reference, by eq. (12) on pixels and by geometry.

    ``areas``/``true_areas``: label -> area number (0: unclassified or not
    seen in all four images); ``columns``: label -> (u11, u12, u21, u22), px;
    ``comparison``: the estimator's count of disagreements by margin.
    ``gain_areas``/``gain_comparison``: the same with each camera's offsets
    divided by its gain (px per encoder step, learnt by the servo from the
    images: no intrinsics), so the magnitude tests compare angles, not pixels
    of two different focal lengths; margins in px at the mean gain.
    """

    reference: Measurement
    areas: dict[str, int]
    true_areas: dict[str, int]
    columns: dict[str, tuple[float, float, float, float]]
    missing: tuple[str, ...]
    comparison: AreaComparison | None
    renders: int
    gain_areas: dict[str, int] = field(default_factory=dict)
    gain_comparison: AreaComparison | None = None


def _touching_blobs(found: dict[str, Detection], gap_px: float = 1.5) -> set[str]:
    """Labels of blobs that touch another label's blob in the same image.

    Where one ball partly hides another, both blobs meet and the hidden one's
    centroid moves by up to its radius, which no single image can tell from a
    shift.  Radii come from the blobs' areas (px): image-only.
    """
    blobs = [
        (name, np.array(d.uv), math.sqrt(d.area_px / math.pi))
        for name, d in found.items()
        if d.found and d.uv is not None
    ]
    out = set()
    for i, (name_a, uv_a, r_a) in enumerate(blobs):
        for name_b, uv_b, r_b in blobs[:i]:
            if float(np.linalg.norm(uv_a - uv_b)) < r_a + r_b + gap_px:
                out |= {name_a, name_b}
    return out


def relative_positioning(
    sim: HeadSim,
    servo: EyeServo,
    reference: Target,
    objects: dict[str, str],
    knowledge: HeadKnowledge | None = None,
    sink: EventSink | None = None,
) -> RelativeRun:
    """Measure ``reference`` with Model 2, then place ``objects`` (body -> colour) in areas.

    The four images (each camera at each step) are taken again at the two
    fixations' whole encoder steps, where the lines L11..L22 are.  An object
    whose blob touches another's in any image (one partly hides the other)
    counts as not seen: its centroid would be biased.
    ``sink``: where the reference's fixation and measurement are reported (None:
    the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    knowledge = knowledge or HeadKnowledge()
    start = sim.render_count
    sink.emit(FixationStarted(reference.name))
    ref = measure_model2(sim, servo, reference, knowledge, Model2Config(midline_px=0.0))
    sink.emit(MeasurementDone(ref))
    if not ref.ok:
        return RelativeRun(ref, {}, {}, {}, tuple(objects), None, sim.render_count - start)
    resolution = sim.settings.encoder_resolution_rad
    # The lines L11..L22 are the cameras' lines of sight at the two fixations
    # (not where a search took a y image).
    steps = (
        round(ref.details["step1_encoder_rad"] / resolution),
        round(ref.details["step2_encoder_rad"] / resolution),
    )
    columns: dict[str, list[float]] = {name: [math.nan] * 4 for name in objects}
    # Order of the four columns: u11 (Ca1, step 1), u12 (Ca1, step 2), u21, u22.
    for step_index, step in enumerate(steps):
        sim.command_eye_steps(step)
        sim.settle()
        for camera in (1, 2):
            found = find_markers(sim.render(camera), objects)
            touching = _touching_blobs(found)
            for name, detection in found.items():
                if detection.found and detection.uv is not None and name not in touching:
                    columns[name][2 * (camera - 1) + step_index] = detection.uv[0]
    seen = [name for name in objects if np.all(np.isfinite(columns[name]))]
    missing = tuple(name for name in objects if name not in seen)
    (u10, _), (u20, _) = knowledge.reference(sim, 1), knowledge.reference(sim, 2)
    alpha1, alpha2 = steps[0] * resolution, steps[1] * resolution
    areas: dict[str, int] = dict.fromkeys(objects, 0)
    true_areas: dict[str, int] = dict.fromkeys(objects, 0)
    comparison = gain_comparison = None
    gain_areas: dict[str, int] = {}
    if seen:
        cols = np.array([columns[name] for name in seen])
        pixel_areas = areas_from_pixels(*cols.T, u10, u20, alpha1=alpha1, alpha2=alpha2)
        truth_h = np.array([sim.position(name, "head") for name in seen])
        effective = (sim.effective_initial_direction(1), sim.effective_initial_direction(2))
        truth = areas_from_geometry(truth_h, alpha1, alpha2, sim.settings.baseline_m, effective)
        comparison = compare_areas(pixel_areas, truth, *cols.T, u10, u20)
        areas.update(zip(seen, (int(a) for a in pixel_areas), strict=True))
        true_areas.update(zip(seen, (int(a) for a in truth), strict=True))
        g1, g2 = (abs(servo.gains.get(camera) or 0.0) for camera in (1, 2))
        if g1 > 0 and g2 > 0:
            gain = areas_from_pixels(*cols.T, u10, u20, alpha1=alpha1, alpha2=alpha2, kx=(g1, g2))
            mean = (g1 + g2) / 2
            scaled = cols.copy()
            scaled[:, :2] = u10 + (cols[:, :2] - u10) * mean / g1
            scaled[:, 2:] = u20 + (cols[:, 2:] - u20) * mean / g2
            gain_comparison = compare_areas(gain, truth, *scaled.T, u10, u20)
            gain_areas = dict(zip(seen, (int(a) for a in gain), strict=True))
    return RelativeRun(
        reference=ref,
        areas=areas,
        true_areas=true_areas,
        columns={name: (c[0], c[1], c[2], c[3]) for name, c in columns.items()},
        missing=missing,
        comparison=comparison,
        renders=sim.render_count - start,
        gain_areas=gain_areas,
        gain_comparison=gain_comparison,
    )


__all__ = [
    "CalibrationError",
    "CalibrationRun",
    "ChessboardRun",
    "HeadKnowledge",
    "LineOfSightTruth",
    "Measurement",
    "Model2Config",
    "RelativeRun",
    "ServoOutcome",
    "Target",
    "TrackingRun",
    "body_target",
    "calibrate_head",
    "calibration_layout",
    "chessboard_corner_target",
    "line_of_sight_truth",
    "measure_chessboard",
    "measure_model1",
    "measure_model2",
    "measure_points_model2",
    "relative_positioning",
    "seen_by_both",
    "to_world",
    "track_moving_target",
]
