"""Model 2 (the two-step measurement of Sec. II-C, the neck still) on each of the scenario's targets."""

from __future__ import annotations

from functools import partial
from typing import Any

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge
from headsim.active.model2 import measure_model2
from headsim.codec import declared
from headsim.procedures.contract import Procedure, register
from headsim.procedures.each_target import measure_targets
from headsim.runs.context import model2_config, servo_config
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord, SurfaceResult
from headsim.scenario.scene import targets_reader
from headsim.scenario.schema import interpolate_option, near_midline_options
from headsim.scenario.spec import CalibrationSpec, Scenario
from headsim.scenario.tables import Table


@declared
class Model2Result(SurfaceResult):
    """Model 2 on each target (the markerless targets: :class:`SurfaceResult`)."""


def run_model2(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], Model2Result]:
    """Model 2 on each target in turn, one eye servo for all."""
    return measure_targets(
        scenario,
        hub,
        knowledge,
        label,
        lambda sim: EyeServo(sim, servo_config(scenario)),
        partial(measure_model2, config=model2_config(scenario)),
        Model2Result,
    )


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: ``interpolate``, and the near-midline remedy's ``midline_px``, ``remedy_px``."""
    return {**interpolate_option(table), **near_midline_options(table)}


MODEL2 = register(
    Procedure(
        "model2",
        "default",
        run_model2,
        Model2Result,
        failures=Model2Result.failures,
        options=read_options,
        read_scene=targets_reader("model2", required=True),
        markerless=True,
        rank=10,
    )
)


__all__ = ["MODEL2", "Model2Result", "run_model2"]
