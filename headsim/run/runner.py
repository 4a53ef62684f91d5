"""Running a scenario: calibrate if asked, run the procedure, collect the results.

The procedures of :mod:`headsim.active` run unchanged.  What a run
shows while it goes (progress, the Rerun recording) follows its events: the
runner gives the simulator (and through it the servos and the procedures) a
:class:`headsim.run.events.Hub` as event sink, and the hub passes every event
on to the run's subscribers.  The runner adds its own events: each recorded
measurement, the calibration block and the finished run.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, fields, replace
from typing import Any, cast

import numpy as np

from headsim import paper
from headsim.active.calibration import (
    CalibrationError,
    CalibrationRun,
    calibrate_head,
    line_of_sight_truth,
)
from headsim.active.chessboard import measure_chessboard
from headsim.active.events import PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.failure import Failure
from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.active.model1 import measure_model1
from headsim.active.model2 import Model2Config, measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.active.placement import calibration_layout
from headsim.active.relative import relative_positioning
from headsim.active.servo_types import Detector, ServoConfig
from headsim.active.tracking import track_moving_target
from headsim.estimators.result import Status
from headsim.run.events import CalibrationDone, Hub, MeasurementRecorded, RunFinished, Subscriber
from headsim.run.outcomes import (
    CalibrationLayout,
    CalibrationReport,
    CalibrationSource,
    CheckTarget,
    ChessboardPaper,
    ChessboardResult,
    Experiment,
    KnowledgeReport,
    LinesOfSightFit,
    MeasurementRecord,
    PointsResult,
    PositionOutcome,
    PursuitFigures,
    PursuitResult,
    RelativeObject,
    RelativePaper,
    RelativeResult,
    RunResult,
    TrackingResult,
    VerticalReference,
)
from headsim.run.serialise import calibration_from_block
from headsim.run.targets import marker_target
from headsim.scenario.calibration_design import near_far_depths, near_fraction
from headsim.scenario.spec import (
    CHESSBOARD_PATTERN,
    CHESSBOARD_SQUARE_M,
    STREAM_CALIBRATION,
    STREAM_DEPTH_NOISE,
    Scenario,
)
from headsim.sim import names
from headsim.sim.simulator import HeadSim
from headsim.vision.crosses import find_cross_point

#: Where unused bodies are parked: under the table, out of every camera's view (W, m).
PARKED_WORLD_M = (0.0, 0.5, -1.0)
#: What the paper reports for each experiment (Sec. VI).
PAPER: dict[str, Any] = {
    "alpha_e_rad": paper.INITIAL_DIRECTIONS_RAD,
    "chessboard_side_mean_m": paper.CHESSBOARD_SIDE_MEAN_M,
    "chessboard_side_std_m": paper.CHESSBOARD_SIDE_STD_M,
    "relative_alpha1_rad": paper.RELATIVE_ALPHA1_RAD,
    "relative_alpha2_rad": paper.RELATIVE_ALPHA2_RAD,
    "relative_objects": paper.RELATIVE_OBJECTS,
}


# -- phases ----------------------------------------------------------------------


def _servo_config(scenario: Scenario) -> ServoConfig:
    return ServoConfig(**asdict(scenario.experiment.servo))


def _model2_config(scenario: Scenario) -> Model2Config:
    e = scenario.experiment
    return Model2Config(interpolate=e.interpolate, midline_px=e.midline_px, remedy_px=e.remedy_px)


def _simulator(hub: Hub, scene: str, scenario: Scenario) -> HeadSim:
    """The scenario's simulator in ``scene``, reporting to ``hub`` (so do its servos and
    the procedures working with it)."""
    return HeadSim(scene, scenario.settings, settle_mode=scenario.settle_mode, sink=hub)


def _told(scenario: Scenario) -> HeadKnowledge:
    """What the scenario tells the head before any calibration: its goal columns, if given."""
    goals = scenario.experiment.goal_columns_px
    return HeadKnowledge() if goals is None else HeadKnowledge(u0=goals)


def _calibrate(scenario: Scenario, hub: Hub) -> tuple[CalibrationRun | None, CalibrationReport]:
    """Sec. V in the default scene; returns the run (None if it failed) and its report."""
    spec = scenario.experiment.calibration
    assert spec is not None
    seed = scenario.seed
    with _simulator(hub, "default", scenario) as sim:
        try:
            positions = calibration_layout(
                sim,
                np.random.default_rng([seed, STREAM_CALIBRATION]),
                spec.targets,
                spec.depth_m,
                spec.lateral,
                spec.vertical,
                depths_m=near_far_depths(spec.targets, spec.depth_m, spec.near_fraction)
                if spec.layout == "near_far"
                else None,
            )
        except ValueError as err:
            report = CalibrationReport(
                status=Status.FAILED,
                detail=f"failed: {err}",
                targets=spec.targets,
                fixated=0,
                renders=0,
                positions=(),
            )
            hub.emit(CalibrationDone(report))
            return None, report
        truth = {f"calibration {k + 1}": p for k, p in enumerate(positions)}
        hub.emit(PhaseStarted("calibration", sim, HeadKnowledge(), truth))
        ball = marker_target(names.CALIBRATION_BALL, names.CALIBRATION_BALL)
        truth_alpha_e = [sim.effective_initial_direction(c) for c in (1, 2)]
        truth_v0 = [sim.camera_settings(c).principal[1] for c in (1, 2)]
        truth_ratio = [sim.camera_settings(c).kx / sim.camera_settings(c).ky for c in (1, 2)]
        planned = CalibrationReport(
            status=Status.OK,
            detail="",
            targets=spec.targets,
            fixated=0,
            renders=0,
            positions=(),
            layout=CalibrationLayout(
                kind=spec.layout,
                near_fraction=(
                    (spec.near_fraction or near_fraction(spec.depth_m))
                    if spec.layout == "near_far"
                    else None
                ),
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
        start = sim.render_count
        previews = hub.previews  # counted apart: images taken are what subscribers see
        try:
            run = calibrate_head(
                sim,
                EyeServo(sim, _servo_config(scenario)),
                ball,
                names.CALIBRATION_BALL,
                positions,
                depth_noise_m=spec.depth_noise_m,
                rng=np.random.default_rng([seed, STREAM_DEPTH_NOISE]),
                extended=spec.extended,
                position_noise_m=spec.position_noise_m,
                lines_of_sight=spec.lines_of_sight,
                knowledge=_told(scenario),
            )
        except ValueError as err:
            outcomes = err.outcomes if isinstance(err, CalibrationError) else ()
            report = replace(
                planned,
                status=Status.FAILED,
                detail=f"failed: {err}",
                renders=sim.render_count - start - (hub.previews - previews),
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
        renders=run.renders - (hub.previews - previews),
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
        knowledge=KnowledgeReport(
            alpha_e_rad=list(knowledge.alpha_e),
            v0_px=list(knowledge.v0),
            kx_over_ky=list(knowledge.kx_over_ky),
            u0_px=list(knowledge.u0),
            los_offset_m=None if knowledge.los_offset_m is None else list(knowledge.los_offset_m),
        ),
    )
    hub.emit(CalibrationDone(report))
    return run, report


def position_outcomes(outcomes: Sequence[Failure | None]) -> tuple[PositionOutcome, ...]:
    """Each calibration position's outcome: fixated (no failure) or the failure."""
    return tuple(PositionOutcome(o) for o in outcomes)


def _lines_fit(run: CalibrationRun, sim: HeadSim) -> LinesOfSightFit:
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


def _record(
    hub: Hub, m: Measurement, knowledge: str, step: int, time_s: float | None = None
) -> MeasurementRecord:
    record = MeasurementRecord(m, knowledge, step, time_s)
    hub.emit(MeasurementRecorded(record))
    return record


def _run_points(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], PointsResult]:
    """Model 2 or Model 1 on each target in turn; after a calibration, also uncalibrated."""
    procedure = scenario.experiment.procedure
    targets = scenario.scene.targets
    records = []
    with _simulator(hub, "default", scenario) as sim:
        truth = {t.name: np.array(t.position_world_m) for t in targets}
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        config = _servo_config(scenario)
        servo: EyeServo | NeckServo
        servo = NeckServo(sim, config) if procedure == "model1" else EyeServo(sim, config)
        passes = (
            [(_told(scenario), "none"), (knowledge, label)]
            if procedure == "calibration"
            else [(knowledge, label)]
        )
        for placement in targets:
            for known, known_label in passes:
                step = hub.begin(placement.name)
                sim.set_body_pose(placement.body, np.array(placement.position_world_m))
                target = marker_target(placement.name, placement.body)
                if procedure == "model1":
                    assert isinstance(servo, NeckServo)
                    m = measure_model1(sim, servo, target, known, scenario.experiment.interpolate)
                else:
                    assert isinstance(servo, EyeServo)
                    m = measure_model2(sim, servo, target, known, _model2_config(scenario))
                records.append(_record(hub, m, known_label, step))
    if procedure != "calibration":
        return records, PointsResult()
    checks = tuple(
        CheckTarget(
            name=before.measurement.name,
            error_m_uncalibrated=_error(before.measurement),
            error_m_calibrated=_error(after.measurement),
        )
        for before, after in zip(records[::2], records[1::2], strict=True)
    )
    return records, PointsResult(check_targets=checks)


def _error(m: Measurement) -> float:
    return float(np.linalg.norm(m.error_head_m)) if m.ok else float("nan")


def _stats(values: np.ndarray) -> tuple[float, float]:
    """Mean and sample standard deviation (NaN where undefined)."""
    mean = float(values.mean()) if values.size else float("nan")
    std = float(values.std(ddof=1)) if values.size > 1 else float("nan")
    return mean, std


def _run_chessboard(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], ChessboardResult]:
    """Every chosen inner corner with Model 2 (Sec. VI-A), and the squares they give."""
    scene = scenario.scene
    assert scene.chessboard is not None
    columns = CHESSBOARD_PATTERN[0]
    indices = (
        list(scene.corners)
        if scene.corners is not None
        else list(range(columns * CHESSBOARD_PATTERN[1]))
    )
    with _simulator(hub, "chessboard", scenario) as sim:
        sim.set_body_pose(names.CHESSBOARD, np.array(scene.chessboard.position_world_m))
        body = sim.data.body(names.CHESSBOARD)
        rotation = body.xmat.reshape(3, 3)
        truth = {
            f"corner_{k % columns}_{k // columns}": body.xpos
            + rotation
            @ np.array(
                [(k % columns) * CHESSBOARD_SQUARE_M, (k // columns) * CHESSBOARD_SQUARE_M, 0.0]
            )
            for k in indices
        }
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        run = measure_chessboard(
            sim,
            EyeServo(sim, _servo_config(scenario)),
            knowledge,
            _model2_config(scenario),
            CHESSBOARD_PATTERN,
            CHESSBOARD_SQUARE_M,
            indices,
        )
        steps = hub.steps
    records = [
        _record(hub, m, label, step) for m, step in zip(run.measurements, steps, strict=True)
    ]
    sides = np.concatenate([run.widths_m, run.heights_m])
    width, height, side = _stats(run.widths_m), _stats(run.heights_m), _stats(sides)
    experiment = ChessboardResult(
        pattern=list(CHESSBOARD_PATTERN),
        square_m=CHESSBOARD_SQUARE_M,
        corners=len(indices),
        corners_measured=run.measured,
        widths_m=run.widths_m,
        heights_m=run.heights_m,
        true_widths_m=run.true_widths_m,
        true_heights_m=run.true_heights_m,
        width_mean_m=width[0],
        width_std_m=width[1],
        height_mean_m=height[0],
        height_std_m=height[1],
        side_mean_m=side[0],
        side_std_m=side[1],
        paper=ChessboardPaper(
            side_mean_m=PAPER["chessboard_side_mean_m"],
            side_std_m=PAPER["chessboard_side_std_m"],
        ),
    )
    return records, experiment


def _run_relative(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], RelativeResult]:
    """The cross point with Model 2, then each object's area S1..S12 (Sec. III, VI-C)."""
    scene = scenario.scene
    assert scene.blocks is not None
    colours = {o.body: names.RELATIVE_OBJECT_COLOURS[o.body] for o in scene.objects}
    with _simulator(hub, "blocks", scenario) as sim:
        for placement in (scene.blocks, *scene.objects):
            sim.set_body_pose(placement.body, np.array(placement.position_world_m))
        for body in scene.parked:
            sim.set_body_pose(body, np.array(PARKED_WORLD_M))
        truth = {p.name: np.array(p.position_world_m) for p in (scene.blocks, *scene.objects)}
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        # A cross point's detection has the status and uv the servo reads; it is never
        # windowed (only blob detectors are), so it stands in for a Detection.
        cross = cast(Detector, find_cross_point)
        reference = Target(names.BLOCKS, cross, lambda s: s.position(names.BLOCKS))
        run = relative_positioning(
            sim, EyeServo(sim, _servo_config(scenario)), reference, colours, knowledge
        )  # the reference's fixation is the phase's one step
        (step,) = hub.steps
        positions_head = {o.body: sim.position(o.body, "head") for o in scene.objects}
    records = [_record(hub, run.reference, label, step)]
    resolution = scenario.settings.encoder_resolution_rad
    details = run.reference.details
    comparison = run.comparison
    seen = [name for name in colours if name not in run.missing]
    margins = dict(zip(seen, comparison.margin, strict=True)) if comparison is not None else {}
    objects = tuple(
        RelativeObject(
            name=name,
            colour=colour,
            area=run.areas.get(name, 0),
            true_area=run.true_areas.get(name, 0),
            agree=name in margins and run.areas[name] == run.true_areas[name],
            margin_px=margins.get(name, float("nan")),
            gain_area=run.gain_areas.get(name, 0),
            gain_agree=name in run.gain_areas and run.gain_areas[name] == run.true_areas[name],
            columns_px=list(run.columns.get(name, (float("nan"),) * 4)),
            position_head_m=positions_head[name],
        )
        for name, colour in colours.items()
    )
    experiment = RelativeResult(
        # The whole encoder steps of the two fixations, where the lines L11..L22 are.
        alpha1_rad=round(details["gamma2_rad"] / resolution) * resolution
        if details
        else float("nan"),
        alpha2_rad=round(details["gamma1_rad"] / resolution) * resolution
        if details
        else float("nan"),
        objects=objects,
        missing=list(run.missing),
        agree=sum(o.agree for o in objects),
        disagree_outside_margin=comparison.n_disagree_outside if comparison else None,
        gain_agree=sum(o.gain_agree for o in objects),
        gain_disagree_outside_margin=run.gain_comparison.n_disagree_outside
        if run.gain_comparison
        else None,
        margin_threshold_px=comparison.threshold_px if comparison else None,
        renders=run.renders,
        paper=RelativePaper(
            alpha1_rad=PAPER["relative_alpha1_rad"],
            alpha2_rad=PAPER["relative_alpha2_rad"],
            objects=PAPER["relative_objects"],
        ),
    )
    return records, experiment


def _run_tracking(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], TrackingResult]:
    """Follow the moving target with Model 1 (neck and eyes), one fixation per time."""
    moving = scenario.scene.moving
    assert moving is not None
    times = moving.times_s
    with _simulator(hub, "default", scenario) as sim:
        truth = {f"{moving.name} {k + 1}": moving.position(float(t)) for k, t in enumerate(times)}
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        target = marker_target(moving.name, moving.body)
        run = track_moving_target(
            sim,
            NeckServo(sim, _servo_config(scenario)),
            target,
            moving.body,
            moving.position,
            times,
            knowledge,
        )
        steps = hub.steps
    records = [
        _record(hub, m, label, step, float(t))
        for m, step, t in zip(run.measurements, steps, times, strict=True)
    ]
    errors = run.errors_world_m
    renders = [m.renders for m in run.measurements]
    experiment = TrackingResult(
        times_s=times,
        waypoints_world_m=list(moving.waypoints_world_m),
        errors_world_m=errors,
        renders_first=renders[0] if renders else 0,
        renders_after_mean=float(np.mean(renders[1:])) if len(renders) > 1 else float("nan"),
    )
    return records, experiment


def _run_pursuit(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], PursuitResult]:
    """The live head pursues a moving target (headsim.run.pursuit)."""
    from headsim.run.pursuit import run_pursuit

    records, block = run_pursuit(scenario, hub, knowledge, label)
    known = {"pursuit", "per_frame", "failures", *(f.name for f in fields(PursuitFigures))}
    if set(block) - known:  # a new figure must get its field, or it would not be written
        raise KeyError(f"pursuit figures without a PursuitFigures field: {set(block) - known}")
    figures = None
    if "frames" in block:
        figures = PursuitFigures(**{f.name: block[f.name] for f in fields(PursuitFigures)})
    return records, PursuitResult(
        pursuit=block["pursuit"],
        figures=figures,
        per_frame=block.get("per_frame"),
        failures=tuple(block.get("failures", ())),
    )


RUNNERS: dict[
    str, Callable[[Scenario, Hub, HeadKnowledge, str], tuple[list[MeasurementRecord], Experiment]]
] = {
    "model2": _run_points,
    "model1": _run_points,
    "calibration": _run_points,
    "chessboard": _run_chessboard,
    "relative_positioning": _run_relative,
    "tracking": _run_tracking,
    "pursuit": _run_pursuit,
}


def calibrate_scenario(
    scenario: Scenario, subscribers: Sequence[Subscriber] = ()
) -> CalibrationReport:
    """Only the scenario's Sec. V calibration (``headsim calibrate``): its report.

    ``status`` is OK or why it failed; ``rendered_frames`` the pixels it
    rendered, in full frames.
    """
    spec = scenario.experiment.calibration
    if spec is None or spec.source is not None:
        raise ValueError("the scenario has no calibration to run ([experiment.calibration])")
    hub = Hub(subscribers)
    _, report = _calibrate(scenario, hub)
    return replace(report, rendered_frames=hub.rendered_frames)


def run_scenario(scenario: Scenario, subscribers: Sequence[Subscriber] = ()) -> RunResult:
    """Run a checked scenario; the subscribers see every image, detection and result."""
    hub = Hub(subscribers)
    timing: dict[str, float] = {}
    renders = {"calibration": 0, "experiment": 0, "recording": 0}
    rendered_frames = {"calibration": 0.0, "experiment": 0.0}
    knowledge, label = _told(scenario), "none"
    calibration = None
    failures: list[str] = []
    spec = scenario.experiment.calibration
    if spec is not None and spec.source is not None:
        from headsim.active.calibration_file import read_calibration

        stored = read_calibration(spec.source, scenario.settings)
        calibration = calibration_from_block(
            stored.block,
            renders=0,
            source=CalibrationSource(
                path=str(stored.path),
                scenario=stored.scenario,
                seed=stored.seed,
                head_hash=stored.head_hash,
                renders=stored.block.get("renders"),
            ),
        )
        hub.emit(CalibrationDone(calibration))
        knowledge, label = stored.knowledge, "calibrated"
    elif spec is not None:
        start = time.perf_counter()
        run, calibration = _calibrate(scenario, hub)
        timing["calibration"] = time.perf_counter() - start
        renders["calibration"] = calibration.renders
        rendered_frames["calibration"] = hub.rendered_frames
        if run is None:
            failures.append(f"calibration: {calibration.status_text}")
        else:
            knowledge, label = run.knowledge, "calibrated"
    records: list[MeasurementRecord] = []
    experiment: Experiment | None = None
    if not failures:
        start = time.perf_counter()
        frames = hub.images
        records, experiment = RUNNERS[scenario.experiment.procedure](
            scenario, hub, knowledge, label
        )
        timing["experiment"] = time.perf_counter() - start
        renders["experiment"] = hub.images - frames
        rendered_frames["experiment"] = hub.rendered_frames - rendered_frames["calibration"]
    failures += [
        f"{r.measurement.name}: {r.measurement.status_text}"
        for r in records
        if not r.measurement.ok
    ]
    if isinstance(experiment, RelativeResult):
        failures += [f"{name}: not seen in all four images" for name in experiment.missing]
    if isinstance(experiment, PursuitResult):
        failures += list(experiment.failures)
    renders["total"] = renders["calibration"] + renders["experiment"]
    timing["total"] = sum(timing.values())
    result = RunResult(
        scenario=scenario,
        calibration=calibration,
        records=tuple(records),
        experiment=experiment,
        renders=renders,
        failures=tuple(failures),
        timing_s=timing,
        rendered_frames={
            **rendered_frames,
            "total": rendered_frames["calibration"] + rendered_frames["experiment"],
        },
        windows={"rendered": hub.windows, "missed": hub.window_misses, "previews": hub.previews},
    )
    hub.emit(RunFinished(result))
    return result


__all__ = [
    "PAPER",
    "Hub",
    "calibrate_scenario",
    "run_scenario",
]
