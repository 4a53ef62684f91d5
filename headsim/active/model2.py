"""Model 2, the two-step measurement of Sec. II-C, with the neck still.

The eye servo (``headsim.active.eye_servo``) fixates the target in camera 1, then
in camera 2; the encoder angles and the other camera's image at each step go
to the pure estimator ``headsim.estimators.model2``.  A target camera 1 does not
see where the eyes are is scanned for over the eye range, and one camera 2
does not see where camera 1 fixates is searched for (``headsim.active.search``);
near the midline the y images are taken again at an intermediate eye angle
(the paper's remedy, generalised).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.active.failure import Failure, detection_failure, servo_failure
from headsim.active.measurement import (
    NOMINAL_PIXEL_SIGMA,
    HeadKnowledge,
    Measurement,
    Target,
    estimated_measurement,
    failed_measurement,
)
from headsim.active.search import find_view, scan_eyes
from headsim.active.servo_types import ServoOutcome, ServoResult
from headsim.estimators import Uncertainty, model2
from headsim.head.servo_head import ServoHead
from headsim.vision.detection import Detection


def _observe(servo: EyeServo, camera: int, target: Target) -> Detection:
    return servo.observe(camera, target.detector)


def _fixation_angle(sim: ServoHead, result: ServoResult, interpolate: bool) -> float:
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


def _nearest_seen(
    seen: Iterable[tuple[int, float, float]], steps: int, goal_u: float, midline_px: float
) -> tuple[int, float, float] | None:
    """From a servo's memory (eye step, u, v), the image nearest eye step ``steps`` whose target is at least
    ``midline_px`` off the goal column (else the one farthest off it)."""
    memory = list(seen)
    if not memory:
        return None
    off = [m for m in memory if abs(m[1] - goal_u) >= midline_px]
    if off:
        return min(off, key=lambda m: abs(m[0] - steps))
    return max(memory, key=lambda m: abs(m[1] - goal_u))


@dataclass
class _Spent:
    """Renders spent finding the target again (``search``, the scan's included) and
    scanning the eye range for it (``scan``)."""

    search: int = 0
    scan: int = 0


@dataclass(frozen=True)
class _Fixated:
    """Both steps converged, and each camera's y image (px) with its eye step."""

    step1: ServoResult
    step2: ServoResult
    uv1: tuple[float, float]
    gamma1_steps: int
    uv2: tuple[float, float]
    gamma2_steps: int


@dataclass(frozen=True)
class _Failed:
    """Why the two steps stopped, and the residuals of the steps that ran, px."""

    failure: Failure
    residuals: tuple[float, ...]


def _two_steps(
    sim: ServoHead,
    servo: EyeServo,
    target: Target,
    goal_u: tuple[float, float],
    midline_px: float,
    spent: _Spent,
) -> _Fixated | _Failed:
    """Step 1 (Ca1 to its goal column ``goal_u[0]``, then Ca2's image), step 2 (Ca2 to
    ``goal_u[1]``, then Ca1's image), with the scan and searches they need."""
    u10, u20 = goal_u
    step1 = servo.run(1, target.detector, goal_u=u10)
    scanned = None
    if step1.outcome is ServoOutcome.TARGET_LOST and step1.iterations == 0:
        # Not in Ca1's view where the last measurement left the eyes: scan the eye
        # range (the start pose first), the neck still.
        before = sim.render_count
        scanned = scan_eyes(servo, 1, target.detector)
        spent.scan = spent.search = sim.render_count - before
        if scanned.found:
            step1 = servo.run(1, target.detector, goal_u=u10, first=scanned.detection)
    if not step1.converged:
        failure = servo_failure(step1, "step 1", 1)
        if scanned is not None and not scanned.found:
            detail = f"{failure.detail}; not seen from the {scanned.tried} eye poses scanned"
            failure = replace(failure, detail=detail)
        return _Failed(failure, (step1.residual_px,))
    seen2 = _observe(servo, 2, target)
    gamma2_steps = step1.steps
    if not seen2.found or seen2.uv is None:
        # Ca2 does not see P where Ca1 fixates it (a lateral target, a long focal
        # length): its y image is taken at an intermediate eye angle where it does,
        # and step 2 starts there.
        before = sim.render_count
        found = find_view(servo, 2, target.detector)
        spent.search += sim.render_count - before
        if found is None:
            searched = f"and at {spent.search} eye angles searched"
            return _Failed(detection_failure(seen2, "step 1", 2, searched), (step1.residual_px,))
        seen2, gamma2_steps = found.detection, found.steps
    # Step 2: Ca2's u to its goal column, starting from that image; then Ca1's image.
    step2 = servo.run(2, target.detector, goal_u=u20, first=seen2)
    residuals = (step1.residual_px, step2.residual_px)
    if not step2.converged:
        return _Failed(servo_failure(step2, "step 2", 2), residuals)
    seen1 = _observe(servo, 1, target)
    gamma1_steps = step2.steps
    uv1_seen = seen1.uv if seen1.found else None
    if uv1_seen is None:
        # Ca1 does not see P where Ca2 fixates it: its y image is one step 1 took.
        memory = _nearest_seen(step1.seen, step2.steps, u10, midline_px)
        if memory is None:
            return _Failed(detection_failure(seen1, "step 2", 1), residuals)
        gamma1_steps, uv1_seen = memory[0], (memory[1], memory[2])
    assert seen2.uv is not None
    return _Fixated(step1, step2, uv1_seen, gamma1_steps, seen2.uv, gamma2_steps)


def measure_model2(
    sim: ServoHead,
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
    spent = _Spent()
    fixed = _two_steps(sim, servo, target, (u10, u20), config.midline_px, spent)
    if isinstance(fixed, _Failed):
        renders = sim.render_count - start
        return failed_measurement(
            sim, target, "model2", fixed.failure, renders, fixed.residuals, spent.search, spent.scan
        )
    step1, step2 = fixed.step1, fixed.step2
    residuals = (step1.residual_px, step2.residual_px)
    search, scan = spent.search, spent.scan
    gamma1_steps, uv1_seen = fixed.gamma1_steps, fixed.uv1
    gamma2_steps = fixed.gamma2_steps

    # The fixation angles come from the two steps; the remedy below replaces y images only.
    alpha1 = _fixation_angle(sim, step1, config.interpolate)
    alpha2 = _fixation_angle(sim, step2, config.interpolate)
    uv1, uv2 = np.array(uv1_seen), np.array(fixed.uv2)
    gamma1, gamma2 = gamma1_steps * resolution, gamma2_steps * resolution
    if min(abs(uv1[0] - u10), abs(uv2[0] - u20)) < config.midline_px:
        remedy = _near_midline_images(sim, servo, target, step1, step2, config)
        if remedy is not None:
            gamma, r1, r2 = remedy
            if r1 is not None and abs(r1[0] - u10) > abs(uv1[0] - u10):
                uv1, gamma1 = r1, gamma
            if r2 is not None and abs(r2[0] - u20) > abs(uv2[0] - u20):
                uv2, gamma2 = r2, gamma

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
    return estimated_measurement(
        sim,
        target,
        "model2",
        estimate,
        start,
        residuals,
        details,
        belief=knowledge.head_belief(sim),
        search=search,
        scan=scan,
    )


def _near_midline_images(
    sim: ServoHead,
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


__all__ = ["Model2Config", "measure_model2"]
