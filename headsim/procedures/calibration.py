"""The calibration procedure: each check target with Model 2 before and after the Sec. V
calibration, and how much better the calibration made it."""

from __future__ import annotations

from typing import Any

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.active.model2 import measure_model2
from headsim.codec import declared, doc
from headsim.procedures.contract import Procedure, register
from headsim.procedures.each_target import measure_each_target
from headsim.runs.context import model2_config, servo_config, told
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.table import format_table, mm
from headsim.scenario.scene import targets_reader
from headsim.scenario.schema import interpolate_option, near_midline_options
from headsim.scenario.spec import CalibrationSpec, Scenario
from headsim.scenario.tables import Table


@declared
class CheckTarget:
    """A check target: its 3-D error before and after the calibration, m (NaN: failed)."""

    name: str = doc("the target")
    error_m_uncalibrated: float = doc("its 3-D error with what the head was told, m (NaN: failed)")
    error_m_calibrated: float = doc("its 3-D error calibrated, m (NaN: failed)")


@declared
class CalibrationCheck:
    """Each check target before and after the calibration."""

    check_targets: tuple[CheckTarget, ...] = doc(
        "each check target, before and after the calibration"
    )

    def summary_lines(self, paper: bool) -> list[str]:
        """The table of each check target's error before and after."""
        rows = [
            [c.name, mm(c.error_m_uncalibrated), mm(c.error_m_calibrated)]
            for c in self.check_targets
        ]
        return [
            "Check targets: error before and after the calibration",
            *format_table(["target", "uncalibrated mm", "calibrated mm"], rows),
        ]


def run_calibration_check(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], CalibrationCheck]:
    """Model 2 on each check target, first with what the head was told, then calibrated."""
    config = model2_config(scenario)
    records = measure_each_target(
        scenario,
        hub,
        knowledge,
        [(told(scenario), "none"), (knowledge, label)],
        lambda sim: EyeServo(sim, servo_config(scenario)),
        lambda sim, servo, target, known: measure_model2(sim, servo, target, known, config),
    )
    checks = tuple(
        CheckTarget(
            name=before.measurement.name,
            error_m_uncalibrated=_error(before.measurement),
            error_m_calibrated=_error(after.measurement),
        )
        for before, after in zip(records[::2], records[1::2], strict=True)
    )
    return records, CalibrationCheck(checks)


def _error(m: Measurement) -> float:
    return float(np.linalg.norm(m.error_head_m)) if m.ok else float("nan")


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: the calibration to run (required), ``interpolate`` and the
    near-midline remedy's ``midline_px``, ``remedy_px``."""
    if calibration is None:
        raise table.fail(
            "calibration", "missing", "an [experiment.calibration] table (the calibration to run)"
        )
    return {**interpolate_option(table), **near_midline_options(table)}


def _fixations(scenario: Scenario) -> int:
    return 2 * len(scenario.scene.targets)  # each check target before and after


CALIBRATION = register(
    Procedure(
        "calibration",
        "default",
        run_calibration_check,
        CalibrationCheck,
        summary=CalibrationCheck.summary_lines,
        options=read_options,
        read_scene=targets_reader("calibration", required=False),
        fixations=_fixations,
        rank=30,
    )
)


__all__ = ["CALIBRATION", "CalibrationCheck", "CheckTarget", "run_calibration_check"]
