"""One-step fixation with independent eyes on each of the scenario's targets (markers,
or ``[scene.room] targets``: clicked points of the textured surfaces, camera 1 tracking
its fovea and camera 2 finding it by correlation): the baseline that the paper's
one-motor design gives up."""

from __future__ import annotations

from functools import partial
from typing import Any

from headsim.active.fixation import fixation_servo, measure_fixation
from headsim.active.measurement import HeadKnowledge
from headsim.active.neck_servo import NeckServo
from headsim.codec import declared
from headsim.head.servo_head import ServoHead
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
class FixationResult(SurfaceResult):
    """One-step fixation on each target (the markerless targets: :class:`SurfaceResult`)."""


def run_fixation(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], FixationResult]:
    """Each target in turn, one servo of both eyes and the neck pitch for all."""

    def servo(sim: ServoHead) -> NeckServo:
        return fixation_servo(sim, config=servo_config(scenario))

    # The servo's first look is with both cameras: points both start images show.
    return measure_targets(
        scenario,
        hub,
        knowledge,
        label,
        servo,
        partial(measure_fixation, interpolate=scenario.experiment.interpolate),
        FixationResult,
        both_views=True,
    )


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: ``interpolate``."""
    return interpolate_option(table)


FIXATION = register(
    Procedure(
        "fixation",
        "default",
        run_fixation,
        FixationResult,
        failures=FixationResult.failures,
        options=read_options,
        read_scene=targets_reader("fixation", required=True),
        needs=frozenset({"independent_eyes"}),
        markerless=True,
        rank=95,
    )
)


__all__ = ["FIXATION", "FixationResult", "run_fixation"]
