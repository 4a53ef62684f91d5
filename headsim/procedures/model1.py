"""Model 1 (fixation with the neck, Sec. II-B) on each of the scenario's targets."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.active.model1 import measure_model1
from headsim.active.neck_servo import NeckServo
from headsim.head.servo_head import ServoHead
from headsim.procedures.contract import Procedure, register
from headsim.procedures.each_target import measure_each_target
from headsim.runs.context import servo_config
from headsim.runs.events import Hub
from headsim.runs.outcomes import SURFACE_FIELDS, MeasurementRecord, SurfaceDraw
from headsim.runs.surface import measure_surface_targets
from headsim.scenario.scene import targets_reader
from headsim.scenario.schema import interpolate_option
from headsim.scenario.spec import CalibrationSpec, Scenario
from headsim.scenario.tables import Table


@dataclass(frozen=True)
class Model1Result:
    """Model 1 on each target; ``surface``: how the markerless targets were
    drawn (None: marker targets)."""

    surface: SurfaceDraw | None = None

    def block(self) -> dict[str, Any]:
        """results.json's ``experiment`` fields: ``surface_targets`` with markerless ones."""
        return {} if self.surface is None else {"surface_targets": self.surface.block()}

    def failures(self) -> tuple[str, ...]:
        """Markerless targets that could not be drawn."""
        return () if self.surface is None or not self.surface.failure else (self.surface.failure,)


def run_model1(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], Model1Result]:
    """Model 1 on each target in turn, one neck servo for all."""
    interpolate = scenario.experiment.interpolate

    def measure(
        sim: ServoHead, servo: NeckServo, target: Target, known: HeadKnowledge
    ) -> Measurement:
        return measure_model1(sim, servo, target, known, interpolate)

    if scenario.scene.surface_targets is not None:
        scored, drawn = measure_surface_targets(
            scenario,
            hub,
            knowledge,
            label,
            lambda sim: NeckServo(sim, servo_config(scenario)),
            measure,
            both_views=True,  # the neck servo's first look is with both cameras
        )
        return scored, Model1Result(drawn)
    records = measure_each_target(
        scenario,
        hub,
        knowledge,
        [(knowledge, label)],
        lambda sim: NeckServo(sim, servo_config(scenario)),
        measure,
    )
    return records, Model1Result()


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: ``interpolate``."""
    return interpolate_option(table)


MODEL1 = register(
    Procedure(
        "model1",
        "default",
        run_model1,
        fields=Model1Result.block,
        failures=Model1Result.failures,
        options=read_options,
        read_scene=targets_reader("model1", required=True),
        needs=frozenset({"neck_yaw"}),
        results=SURFACE_FIELDS,
        markerless=True,
        reach="model1",
        rank=20,
    )
)


__all__ = ["MODEL1", "Model1Result", "run_model1"]
