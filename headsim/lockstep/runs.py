"""Many scenario runs with their Model 2 measurements in lockstep (a sweep's chunk).

Each scenario is calibrated on the classic path (:func:`headsim.runs.calibrate.calibrate`:
lockstep does not fixate calibration balls), then every target of every scenario is a
head of one :class:`~headsim.lockstep.settled.SettledHeads` (each with its scenario's
settings and what its calibration told it), measured together
(:func:`~headsim.lockstep.servo.measure_model2_heads`).  A run comes back as the classic
runner's :class:`~headsim.runs.result.RunResult`, so its consumers read it unchanged
(estimates in H; the world estimate is not computed, NaN).  A scenario lockstep cannot
run (another procedure, a room, physics settling, a stored calibration) or one of
whose targets needs the classic scan or search comes back as the reason instead, for
the caller to run on the classic path.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from headsim.active.calibration_report import CalibrationReport
from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.estimators.result import Method, Status
from headsim.procedures.model2 import Model2Result
from headsim.runs.calibrate import calibrate
from headsim.runs.context import model2_config, servo_config, told
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord, RunRenders
from headsim.runs.result import RunResult
from headsim.scenario.spec import Placement, Scenario
from headsim.sim.events import RenderCounts
from headsim.sim.model import BuiltModel, build_model

from .model2_run import scenario_targets
from .servo import NEEDS_CLASSIC, HeadEstimate, HeadJob, measure_model2_heads
from .settled import DEFAULT_SCENE, SettledHeads


def classic_reason(scenario: Scenario) -> str:
    """Why lockstep leaves ``scenario`` to the classic path ("" where it runs it)."""
    if scenario.experiment.procedure != "model2":
        return f"procedure {scenario.experiment.procedure!r} (lockstep runs model2)"
    if scenario.scene.surface_targets is not None:
        return "markerless targets (lockstep finds markers)"
    if not scenario.scene.targets:
        return "no targets"
    if scenario.scene.room is not None:
        return "a textured room (lockstep draws the default scene)"
    if scenario.settle_mode != "kinematic":
        return f"settle_mode {scenario.settle_mode!r} (lockstep settles kinematically)"
    spec = scenario.experiment.calibration
    if spec is not None and spec.source is not None:
        return "a stored calibration (read by the classic runner)"
    return ""


@dataclass
class _Pending:
    """A calibrated scenario waiting for its heads' measurements."""

    row: int
    scenario: Scenario
    knowledge: HeadKnowledge
    label: str
    calibration: CalibrationReport | None
    renders: RenderCounts
    timing_s: dict[str, float]
    built: BuiltModel


@dataclass(frozen=True)
class LockstepStats:
    """What a chunk drew: eye images through the one context, heads, scenarios run."""

    images: int
    heads: int
    scenarios: int
    render_s: float


def run_scenarios(
    scenarios: Sequence[Scenario],
) -> tuple[list[RunResult | str], LockstepStats]:
    """Each of ``scenarios`` run (its calibration classic, its measurements in lockstep
    with every other's): its result, or why the classic path must run it."""
    out: list[RunResult | str] = [classic_reason(s) for s in scenarios]
    pending: list[_Pending] = []
    for row, scenario in enumerate(scenarios):
        if out[row]:
            continue
        knowledge, label = told(scenario), "none"
        calibration: CalibrationReport | None = None
        renders, timing = RenderCounts(), {}
        if scenario.experiment.calibration is not None:
            start = time.perf_counter()
            run, calibration = calibrate(scenario, Hub(()))
            timing["calibration"] = time.perf_counter() - start
            renders = calibration.renders
            if run is None:
                failed = (f"calibration: {calibration.status_text}",)
                out[row] = _result(
                    scenario, calibration, (), renders, RenderCounts(), timing, failed
                )
                continue
            knowledge, label = run.knowledge, "calibrated"
        # Built now, while the lens's canvas the calibration made is still cached.
        built = build_model(DEFAULT_SCENE, scenario.settings)
        pending.append(
            _Pending(row, scenario, knowledge, label, calibration, renders, timing, built)
        )
    jobs: list[HeadJob] = []
    owners: list[int] = []
    settings = []
    builds = []
    for index, p in enumerate(pending):
        model2, servo = model2_config(p.scenario), servo_config(p.scenario)
        for target in scenario_targets(p.scenario):
            jobs.append(HeadJob(target, p.knowledge, model2, servo))
            owners.append(index)
            settings.append(p.scenario.settings)
            builds.append(p.built)
    if not jobs:
        return out, LockstepStats(0, 0, 0, 0.0)
    start = time.perf_counter()
    with SettledHeads(settings, built=builds) as heads:
        head = 0
        for p in pending:
            placed = p.scenario.scene.targets
            for k in range(len(placed)):
                for body in placed[: k + 1]:
                    heads.place(head, body.body, np.array(body.position_world_m))
                head += 1
        estimates = measure_model2_heads(heads, jobs)
        stats = LockstepStats(heads.images, heads.n, len(pending), 0.0)
    spent = time.perf_counter() - start
    stats = LockstepStats(stats.images, stats.heads, stats.scenarios, spent)
    for index, p in enumerate(pending):
        mine = [e for e, owner in zip(estimates, owners, strict=True) if owner == index]
        waiting = [e for e in mine if e.status == NEEDS_CLASSIC]
        if waiting:
            out[p.row] = f"{waiting[0].name}: {waiting[0].detail}"
            continue
        records = tuple(
            MeasurementRecord(_measurement(e, t), p.label, step)
            for step, (e, t) in enumerate(zip(mine, p.scenario.scene.targets, strict=True))
        )
        # The heads' images, as windows (the servo's looks) are not told apart here.
        drawn = RenderCounts(images=sum(e.renders for e in mine))
        p.timing_s["experiment"] = spent * len(mine) / len(jobs)
        out[p.row] = _result(p.scenario, p.calibration, records, p.renders, drawn, p.timing_s)
    return out, stats


def _measurement(estimate: HeadEstimate, placed: Placement) -> Measurement:
    """``estimate`` as the classic path's measurement record holds it."""
    position = np.array(placed.position_world_m)
    return Measurement(
        name=estimate.name,
        method=Method.MODEL2,
        status=Status.OK if estimate.ok else Status.FAILED,
        estimate_head_m=estimate.estimate_head_m,
        truth_head_m=estimate.truth_head_m,
        estimate_world_m=np.full(3, np.nan),
        truth_world_m=position,
        covariance_head_m2=np.full((3, 3), np.nan),
        renders=estimate.renders,
        servo_residual_px=estimate.residuals_px,
        detail=estimate.detail,
        failure=estimate.failure,
    )


def _result(
    scenario: Scenario,
    calibration: CalibrationReport | None,
    records: tuple[MeasurementRecord, ...],
    calibration_renders: RenderCounts,
    experiment_renders: RenderCounts,
    timing: dict[str, float],
    failed: tuple[str, ...] = (),
) -> RunResult:
    """The run as the classic runner reports it (``failed``: the calibration's failure)."""
    failures = list(failed)
    failures += [
        f"{r.measurement.name}: {r.measurement.status_text}"
        for r in records
        if not r.measurement.ok
    ]
    return RunResult(
        scenario=scenario,
        calibration=calibration,
        records=records,
        experiment=Model2Result(),
        renders=RunRenders(
            calibration=calibration_renders,
            experiment=experiment_renders,
            in_measurements=sum(r.measurement.renders for r in records),
        ),
        failures=tuple(failures),
        timing_s={**timing, "total": sum(timing.values())},
    )


__all__ = ["LockstepStats", "classic_reason", "run_scenarios"]
