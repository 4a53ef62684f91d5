"""Model 1 (fixation with the neck, Sec. II-B) on each of the scenario's targets."""

from __future__ import annotations

from functools import partial
from typing import Any

from headsim.active.measurement import HeadKnowledge
from headsim.active.model1 import measure_model1
from headsim.active.neck_servo import NeckServo
from headsim.codec import declared
from headsim.procedures.contract import Procedure, register
from headsim.procedures.each_target import measure_targets
from headsim.runs.context import servo_config
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord, SurfaceResult
from headsim.scenario.scene import targets_reader
from headsim.scenario.schema import interpolate_option
from headsim.scenario.spec import CalibrationSpec, Scenario
from headsim.scenario.tables import Table


@declared
class Model1Result(SurfaceResult):
    """Model 1 on each target (the markerless targets: :class:`SurfaceResult`)."""


def run_model1(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], Model1Result]:
    """Model 1 on each target in turn, one neck servo for all."""
    return measure_targets(
        scenario,
        hub,
        knowledge,
        label,
        lambda sim: NeckServo(sim, servo_config(scenario)),
        partial(measure_model1, interpolate=scenario.experiment.interpolate),
        Model1Result,
        both_views=True,  # the neck servo's first look is with both cameras
    )


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: ``interpolate``."""
    return interpolate_option(table)


MODEL1 = register(
    Procedure(
        "model1",
        "default",
        run_model1,
        Model1Result,
        failures=Model1Result.failures,
        options=read_options,
        read_scene=targets_reader("model1", required=True),
        needs=frozenset({"neck_yaw"}),
        markerless=True,
        reach="model1",
        rank=20,
    )
)


__all__ = ["MODEL1", "Model1Result", "run_model1"]
