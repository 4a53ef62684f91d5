"""Model 1 or Model 2 on each of the scenario's targets; for the calibration procedure,
each check target before and after the calibration."""

from __future__ import annotations

from dataclasses import asdict
from typing import Any

import numpy as np

from headsim.active.events import PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.active.model1 import measure_model1
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.run.context import (
    model2_config,
    record_measurement,
    servo_config,
    simulator,
    told,
)
from headsim.run.events import Hub
from headsim.run.outcomes import (
    CheckTarget,
    MeasurementRecord,
    PointsResult,
)
from headsim.run.table import format_table, mm
from headsim.run.targets import marker_target
from headsim.scenario.registry import Procedure, register
from headsim.scenario.spec import Scenario


def run_points(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], PointsResult]:
    """Model 2 or Model 1 on each target in turn; after a calibration, also uncalibrated."""
    procedure = scenario.experiment.procedure
    targets = scenario.scene.targets
    records = []
    with simulator(hub, "default", scenario) as sim:
        truth = {t.name: np.array(t.position_world_m) for t in targets}
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        config = servo_config(scenario)
        servo: EyeServo | NeckServo
        servo = NeckServo(sim, config) if procedure == "model1" else EyeServo(sim, config)
        passes = (
            [(told(scenario), "none"), (knowledge, label)]
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
                    m = measure_model2(sim, servo, target, known, model2_config(scenario))
                records.append(record_measurement(hub, m, known_label, step))
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


def _check_lines(e: PointsResult) -> list[str]:
    rows = [
        [c.name, mm(c.error_m_uncalibrated), mm(c.error_m_calibrated)]
        for c in e.check_targets or ()
    ]
    return [
        "Check targets: error before and after the calibration",
        *format_table(["target", "uncalibrated mm", "calibrated mm"], rows),
    ]


def _fields(e: PointsResult) -> dict[str, Any]:
    if e.check_targets is None:
        return {}
    return {"check_targets": [asdict(c) for c in e.check_targets]}


def _summary(e: PointsResult, paper: bool) -> list[str]:
    return [] if e.check_targets is None else _check_lines(e)


MODEL2, MODEL1, CALIBRATION = (
    register(Procedure(name, "default", run_points, fields=_fields, summary=_summary))
    for name in ("model2", "model1", "calibration")
)


__all__ = ["CALIBRATION", "MODEL1", "MODEL2", "run_points"]
