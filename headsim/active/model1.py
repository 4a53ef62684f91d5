"""Model 1, fixation with the neck (Sec. II-B): neck and eyes put the target on
both goal columns, then eqs. (2)-(3) give its position in H and W.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from headsim.active.failure import neck_failure
from headsim.active.look import foveal_detector
from headsim.active.measurement import (
    HeadKnowledge,
    Measurement,
    Target,
    encoder_sigma_rad,
    estimated_measurement,
    failed_measurement,
)
from headsim.active.neck_servo import NeckServo
from headsim.active.search import find_neck_view, scan_neck
from headsim.active.servo_types import ServoOutcome
from headsim.estimators import Uncertainty, model1
from headsim.head.servo_head import ServoHead


def measure_model1(
    sim: ServoHead,
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
    ``search_renders``.  A new target (no ``last_seen``) is looked for first
    from the start pose: where the neck was left belongs to another target
    (looking there first missed a quarter of the targets and cost 1.1 more
    renders per point).  Where the start pose does not show it to both
    cameras, the neck scans its ranges with the eyes at 0
    (:func:`headsim.active.search.scan_neck`, counted in ``scan_renders``)
    and the servo fixates from where both see it; not for a foveal (markerless)
    detector, which a scan's whole frames cannot serve.
    """
    knowledge = knowledge or HeadKnowledge()
    start = sim.render_count
    (u10, v10), (u20, v20) = knowledge.reference(sim, 1), knowledge.reference(sim, 2)
    goals = (u10, u20, (v10 + v20) / 2)
    if not last_seen and any(servo.steps()):
        sim.command(neck_yaw=0.0, neck_pitch=0.0, eye=0.0)
        sim.settle()
    result = servo.run(target.detector, goals=goals)
    search = scan = 0
    scanned = None
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
        scannable = foveal_detector(target.detector) is None
        if (
            scannable
            and found is None
            and result.outcome is ServoOutcome.TARGET_LOST
            and not result.iterations
        ):
            # Not in both views from the start pose either: scan the neck's ranges.  (A
            # markerless target, clicked in camera 1's start image, is correlated in
            # foveal windows only: a scan's previews and whole frames cannot show it.)
            before = sim.render_count
            scanned = scan_neck(servo, target.detector)
            scan = sim.render_count - before
            search += scan
            if scanned.found:
                result = servo.run(target.detector, goals=goals)
    residual = (result.residual_px,)
    if not result.converged:
        failure = neck_failure(result)
        if scanned is not None and not scanned.found:
            detail = (
                f"{failure.detail}; not seen by both from the {scanned.tried} neck poses scanned"
            )
            failure = replace(failure, detail=detail)
        return failed_measurement(
            sim,
            target,
            "model1",
            failure,
            sim.render_count - start,
            residual,
            search,
            scan,
        )
    resolution = sim.settings.encoder_resolution_rad
    yaw, pitch, eye = (
        s * resolution for s in (result.subpixel_steps if interpolate else result.steps)
    )
    angle_sigma = encoder_sigma_rad(resolution, interpolate)
    belief = knowledge.head_belief(sim)
    estimate = model1(
        [eye],
        belief.baseline_m,
        alpha_e=knowledge.alpha_e,
        uncertainty=Uncertainty(encoder=angle_sigma),
        los_offset_m=knowledge.line_of_sight_offsets(sim),
    )
    details = {"alpha_rad": eye, "neck_yaw_rad": yaw, "neck_pitch_rad": pitch}
    return estimated_measurement(
        sim,
        target,
        "model1",
        estimate,
        start,
        residual,
        details,
        (yaw, pitch),
        belief,
        search,
        scan,
    )


__all__ = ["measure_model1"]
