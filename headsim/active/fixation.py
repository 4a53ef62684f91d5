"""One-step fixation with independent eyes: both eye motors and the neck pitch put the
target on both goal columns and the goal row at once; the position follows from the two
eye angles and the baseline (docs/equations.md, "Beyond the paper: other heads")."""

from __future__ import annotations

from headsim.active.failure import neck_failure
from headsim.active.measurement import (
    HeadKnowledge,
    Measurement,
    Target,
    encoder_sigma_rad,
    estimated_measurement,
    failed_measurement,
)
from headsim.active.neck_servo import NeckServo
from headsim.estimators import Uncertainty
from headsim.estimators.fixation import fixation
from headsim.head.servo_head import ServoHead

#: The motors a one-step fixation drives, in the order of its servo's steps: the
#: errors (u1 - u10, u2 - u20, mean v - v0) fall on them one each.
FIXATION_MOTORS = ("eye", "eye2", "neck_pitch")


def fixation_servo(sim: ServoHead, servo: NeckServo | None = None, **kwargs: object) -> NeckServo:
    """The servo of a one-step fixation on ``sim``'s head, which needs independent eyes."""
    if "eye2" not in sim.motors:
        raise ValueError("a one-step fixation needs a head with a motor per eye")
    return NeckServo(sim, motors=FIXATION_MOTORS, **kwargs)  # type: ignore[arg-type]


def measure_fixation(
    sim: ServoHead,
    servo: NeckServo,
    target: Target,
    knowledge: HeadKnowledge | None = None,
    interpolate: bool = True,
) -> Measurement:
    """Both eyes and the neck pitch fixate the target from the start pose (neck yaw
    held where it is), then the two eye angles give its position in H."""
    knowledge = knowledge or HeadKnowledge()
    start = sim.render_count
    (u10, v10), (u20, v20) = knowledge.reference(sim, 1), knowledge.reference(sim, 2)
    goals = (u10, u20, (v10 + v20) / 2)
    if any(servo.steps()):
        sim.command(eye=0.0, eye2=0.0, neck_pitch=0.0)
        sim.settle()
    result = servo.run(target.detector, goals=goals)
    residual = (result.residual_px,)
    if not result.converged:
        return failed_measurement(
            sim, target, "fixation", neck_failure(result), sim.render_count - start, residual
        )
    resolution = sim.settings.encoder_resolution_rad
    alpha1, alpha2, pitch = (
        s * resolution for s in (result.subpixel_steps if interpolate else result.steps)
    )
    yaw = sim.neck_encoders()[0]
    sigma = encoder_sigma_rad(resolution, interpolate)
    belief = knowledge.head_belief(sim)
    estimate = fixation(
        [alpha1],
        [alpha2],
        belief.baseline_m,
        alpha_e=knowledge.alpha_e,
        uncertainty=Uncertainty(encoder=sigma),
        los_offset_m=knowledge.line_of_sight_offsets(sim),
    )
    details = {"alpha1_rad": alpha1, "alpha2_rad": alpha2, "neck_pitch_rad": pitch}
    return estimated_measurement(
        sim, target, "fixation", estimate, start, residual, details, (yaw, pitch), belief
    )


__all__ = ["FIXATION_MOTORS", "fixation_servo", "measure_fixation"]
