"""The Sec. V calibration phase in the default scene, and its report (ball layout, fit,
each position's outcome, the extended line-of-sight fit beside the truth)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from headsim.active.calibration import (
    CalibrationError,
    CalibrationRun,
    calibrate_head,
    line_of_sight_truth,
)
from headsim.active.calibration_report import (
    CalibrationLayout,
    CalibrationReport,
    KnowledgeReport,
    LinesOfSightFit,
    PositionOutcome,
    VerticalReference,
)
from headsim.active.events import PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.failure import Failure
from headsim.active.measurement import HeadKnowledge
from headsim.active.placement import calibration_layout
from headsim.estimators.result import Status
from headsim.head.servo_head import ServoHead
from headsim.runs.context import (
    PAPER,
    PARKED_WORLD_M,
    head,
    servo_config,
    told,
)
from headsim.runs.events import CalibrationDone, Hub
from headsim.runs.targets import marker_target
from headsim.scenario.calibration_design import near_far_depths, near_fraction
from headsim.scenario.spec import STREAM_CALIBRATION, STREAM_DEPTH_NOISE, Scenario
from headsim.sim import names
from headsim.sim.events import RenderCounts


def calibrate(scenario: Scenario, hub: Hub) -> tuple[CalibrationRun | None, CalibrationReport]:
    """Sec. V in the default scene; returns the run (None if it failed) and its report."""
    spec = scenario.experiment.calibration
    assert spec is not None
    seed = scenario.seed
    start = hub.renders  # every image this phase draws is one of its renders
    near_far = spec.layout == "near_far"
    config, known = servo_config(scenario), told(scenario)
    with head(hub, "default", scenario) as sim:
        # The ball alone in the scene, as on a bench: the markers where the scene's XML
        # puts them stand among the ball's positions and would hide some of them.
        for marker in names.MARKERS:
            sim.truth.set_body_pose(marker, np.array(PARKED_WORLD_M))
        try:
            depths_m = (
                near_far_depths(spec.targets, spec.depth_m, spec.near_fraction)
                if near_far
                else None
            )
            near = (spec.near_fraction or near_fraction(spec.depth_m)) if near_far else None
            positions = (
                calibration_layout(
                    sim.truth.stereo_views(),
                    np.random.default_rng([seed, STREAM_CALIBRATION]),
                    spec.targets,
                    spec.depth_m,
                    spec.lateral,
                    spec.vertical,
                    depths_m=depths_m,
                )
                if spec.positions_world_m is None
                else np.array(spec.positions_world_m)
            )
        except ValueError as err:
            report = CalibrationReport(
                status=Status.FAILED,
                detail=f"failed: {err}",
                targets=spec.targets,
                fixated=0,
                renders=hub.renders - start,
                positions=(),
            )
            hub.emit(CalibrationDone(report))
            return None, report
        truth = {f"calibration {k + 1}": p for k, p in enumerate(positions)}
        hub.emit(PhaseStarted("calibration", sim.truth, HeadKnowledge(), truth))
        ball = marker_target(names.CALIBRATION_BALL, names.CALIBRATION_BALL)
        # At the servo's goal columns, as the fit's error is (the image centres by default).
        truth_alpha_e = [
            sim.truth.effective_initial_direction(c, known.reference(sim, c)[0]) for c in (1, 2)
        ]
        truth_v0 = [sim.truth.camera_settings(c).principal[1] for c in (1, 2)]
        truth_ratio = [
            sim.truth.camera_settings(c).kx / sim.truth.camera_settings(c).ky for c in (1, 2)
        ]
        planned = CalibrationReport(
            status=Status.OK,
            detail="",
            targets=spec.targets,
            fixated=0,
            renders=RenderCounts(),
            positions=(),
            layout=CalibrationLayout(
                kind=spec.layout if spec.positions_world_m is None else "given",
                near_fraction=near,
                depth_m=list(spec.depth_m),
                lateral=spec.lateral,
                vertical=spec.vertical,
                positions_world_m=positions,
            ),
            depth_noise_m=spec.depth_noise_m,
            position_noise_m=spec.position_noise_m,
            lines_of_sight_fit=spec.lines_of_sight,
            extended=spec.extended,
            alpha_e_truth_rad=truth_alpha_e,
            alpha_e_paper_rad=list(PAPER["alpha_e_rad"]),
        )
        try:
            run = calibrate_head(
                sim,
                EyeServo(sim, config),
                ball,
                names.CALIBRATION_BALL,
                positions,
                depth_noise_m=spec.depth_noise_m,
                rng=np.random.default_rng([seed, STREAM_DEPTH_NOISE]),
                extended=spec.extended,
                position_noise_m=spec.position_noise_m,
                lines_of_sight=spec.lines_of_sight,
                knowledge=known,
            )
        except ValueError as err:
            outcomes = err.outcomes if isinstance(err, CalibrationError) else ()
            report = replace(
                planned,
                status=Status.FAILED,
                detail=f"failed: {err}",
                renders=hub.renders - start,
                fixated=sum(o is None for o in outcomes),
                positions=position_outcomes(outcomes),
            )
            hub.emit(CalibrationDone(report))
            return None, report
    fit, knowledge = run.fit, run.knowledge
    report = replace(
        planned,
        fixated=run.samples,
        positions=position_outcomes(run.outcomes),
        renders=hub.renders - start,
        alpha_e_rad=list(fit.alpha_e),
        alpha_e_std_rad=list(fit.std_errors),
        alpha_e_covariance_rad2=np.asarray(fit.covariance).tolist(),
        alpha_e_error_rad=list(run.alpha_e_error),
        converged=bool(fit.converged),
        depth_residual_rms_m=float(np.sqrt(np.mean(np.square(fit.depth_residuals)))),
        vertical_reference=None
        if run.vertical is None
        else VerticalReference(
            v0_px=[v.v0 for v in run.vertical],
            v0_std_px=[v.v0_std for v in run.vertical],
            v0_truth_px=truth_v0,
            kx_over_ky=[v.kx_over_ky for v in run.vertical],
            kx_over_ky_std=[v.kx_over_ky_std for v in run.vertical],
            kx_over_ky_truth=truth_ratio,
        ),
        lines_of_sight=None if run.lines is None else _lines_fit(run, sim),
        knowledge=KnowledgeReport.of(knowledge),
    )
    hub.emit(CalibrationDone(report))
    return run, report


def position_outcomes(outcomes: Sequence[Failure | None]) -> tuple[PositionOutcome, ...]:
    """Each calibration position's outcome: fixated (no failure) or the failure."""
    return tuple(PositionOutcome(o) for o in outcomes)


def _lines_fit(run: CalibrationRun, sim: ServoHead) -> LinesOfSightFit:
    """The extended line-of-sight fit beside the truth."""
    lines = run.lines
    assert lines is not None
    truth = line_of_sight_truth(sim, run.knowledge)
    return LinesOfSightFit(
        alpha_e_rad=list(lines.alpha_e),
        offset_m=list(lines.offset_m),
        std_errors_alpha_e_rad=list(lines.std_errors[:2]),
        std_errors_offset_m=list(lines.std_errors[2:]),
        offset_truth_m=list(truth.offset_m),
        covariance=np.asarray(lines.covariance).tolist(),  # (alpha_e1, alpha_e2, s1, s2)
        effective_baseline_m=lines.effective_baseline_m,
        effective_baseline_std_m=lines.effective_baseline_std_m,
        effective_baseline_truth_m=truth.effective_baseline_m,
        separable=lines.separable,
        message=lines.message,
    )


__all__ = ["calibrate", "position_outcomes"]
