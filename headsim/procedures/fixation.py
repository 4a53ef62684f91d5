"""One-step fixation with independent eyes on each of the scenario's targets: the
baseline that the paper's one-motor design gives up."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from headsim.active.fixation import fixation_servo, measure_fixation
from headsim.active.measurement import HeadKnowledge
from headsim.procedures.each_target import measure_each_target
from headsim.run.context import servo_config
from headsim.run.events import Hub
from headsim.run.outcomes import MeasurementRecord
from headsim.scenario.registry import Procedure, register
from headsim.scenario.scene import targets_reader
from headsim.scenario.schema import interpolate_option
from headsim.scenario.spec import CalibrationSpec, Scenario
from headsim.scenario.tables import Table


@dataclass(frozen=True)
class FixationResult:
    """One-step fixation on each target: nothing beyond its measurements."""

    def block(self) -> dict[str, Any]:
        """results.json's ``experiment`` fields: none."""
        return {}


def run_fixation(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], FixationResult]:
    """Each target in turn, one servo of both eyes and the neck pitch for all."""
    interpolate = scenario.experiment.interpolate
    records = measure_each_target(
        scenario,
        hub,
        knowledge,
        [(knowledge, label)],
        lambda sim: fixation_servo(sim, config=servo_config(scenario)),
        lambda sim, servo, target, known: measure_fixation(sim, servo, target, known, interpolate),
    )
    return records, FixationResult()


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: ``interpolate``."""
    return interpolate_option(table)


FIXATION = register(
    Procedure(
        "fixation",
        "default",
        run_fixation,
        fields=FixationResult.block,
        options=read_options,
        read_scene=targets_reader("fixation", required=True),
        needs=frozenset({"independent_eyes"}),
    )
)


__all__ = ["FIXATION", "FixationResult", "run_fixation"]
