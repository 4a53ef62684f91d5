"""What every phase of a run builds from its scenario: the simulator reporting to the
run's hub, the servo and Model 2 settings, what the head is told before a calibration,
where unused bodies park, the paper's figures, and each measurement's record."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict
from typing import Any

from headsim import paper
from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.active.model2 import Model2Config
from headsim.active.servo_types import ServoConfig
from headsim.head.sim_head import SimHead
from headsim.runs.events import Hub, MeasurementRecorded
from headsim.runs.outcomes import FixationScore, MeasurementRecord
from headsim.scenario.spec import Scenario
from headsim.sim.simulator import HeadSim

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


def servo_config(scenario: Scenario) -> ServoConfig:
    return ServoConfig(**asdict(scenario.experiment.servo))


def model2_config(scenario: Scenario) -> Model2Config:
    e = scenario.experiment
    return Model2Config(interpolate=e.interpolate, midline_px=e.midline_px, remedy_px=e.remedy_px)


def simulator(hub: Hub, scene: str, scenario: Scenario) -> HeadSim:
    """The scenario's simulator in ``scene``, reporting to ``hub`` (so do its servos and
    the procedures working with it)."""
    return HeadSim(
        scene,
        scenario.settings,
        settle_mode=scenario.settle_mode,
        sink=hub,
        room=scenario.scene.room,
    )


@contextmanager
def head(hub: Hub, scene: str, scenario: Scenario) -> Iterator[SimHead]:
    """The scenario's simulator in ``scene`` as the head the servos and procedures drive
    (:class:`~headsim.head.servo_head.ServoHead`; its truth channel for placing and
    scoring), reporting to ``hub``; closed on leaving."""
    with simulator(hub, scene, scenario) as sim:
        yield SimHead(sim)


def told(scenario: Scenario) -> HeadKnowledge:
    """What the scenario tells the head before any calibration: its goal columns, if given."""
    goals = scenario.experiment.goal_columns_px
    return HeadKnowledge() if goals is None else HeadKnowledge(u0=goals)


def record_measurement(
    hub: Hub,
    m: Measurement,
    knowledge: str,
    step: int,
    time_s: float | None = None,
    fixation: FixationScore | None = None,
) -> MeasurementRecord:
    record = MeasurementRecord(m, knowledge, step, time_s, fixation)
    hub.emit(MeasurementRecorded(record))
    return record


__all__ = [
    "PAPER",
    "PARKED_WORLD_M",
    "head",
    "model2_config",
    "record_measurement",
    "servo_config",
    "simulator",
    "told",
]
