"""Tracking a moving target with Model 1 (neck and eyes), one fixation per time."""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from headsim.active.events import PhaseStarted
from headsim.active.measurement import HeadKnowledge
from headsim.active.neck_servo import NeckServo
from headsim.active.tracking import track_moving_target
from headsim.run.context import (
    record_measurement,
    servo_config,
    simulator,
)
from headsim.run.events import Hub
from headsim.run.outcomes import (
    MeasurementRecord,
    TrackingResult,
)
from headsim.run.table import cell, mm
from headsim.run.targets import marker_target
from headsim.scenario.registry import Procedure, register
from headsim.scenario.spec import Scenario


def run_tracking(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], TrackingResult]:
    """Follow the moving target with Model 1 (neck and eyes), one fixation per time."""
    moving = scenario.scene.moving
    assert moving is not None
    times = moving.times_s
    with simulator(hub, "default", scenario) as sim:
        truth = {f"{moving.name} {k + 1}": moving.position(float(t)) for k, t in enumerate(times)}
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        target = marker_target(moving.name, moving.body)
        run = track_moving_target(
            sim,
            NeckServo(sim, servo_config(scenario)),
            target,
            moving.body,
            moving.position,
            times,
            knowledge,
        )
        steps = hub.steps
    records = [
        record_measurement(hub, m, label, step, float(t))
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


def _tracking_lines(e: TrackingResult) -> list[str]:
    errors = np.asarray(e.errors_world_m, dtype=float)
    finite = errors[np.isfinite(errors)]
    return [
        f"Tracking with the neck (Model 1): {len(finite)} of {len(errors)} fixations; error in W "
        f"mean {mm(float(finite.mean()) if finite.size else None)} mm, max "
        f"{mm(float(finite.max()) if finite.size else None)} mm; renders {e.renders_first} for the "
        f"first fixation, {cell(e.renders_after_mean, '.1f')} per fixation after"
    ]


def _summary(e: TrackingResult, paper: bool) -> list[str]:
    return _tracking_lines(e)


TRACKING = register(Procedure("tracking", "default", run_tracking, fields=asdict, summary=_summary))


__all__ = ["TRACKING", "run_tracking"]
