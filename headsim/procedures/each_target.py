"""What Model 2, Model 1 and the calibration procedure share: one servo measuring each of
the scenario's targets in turn, in the default scene."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

import numpy as np

from headsim.active.events import PhaseStarted
from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.head.servo_head import ServoHead
from headsim.runs.context import head, record_measurement
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.targets import marker_target
from headsim.scenario.spec import Scenario

S = TypeVar("S")


def measure_each_target(
    scenario: Scenario,
    hub: Hub,
    knowledge: HeadKnowledge,
    passes: Sequence[tuple[HeadKnowledge, str]],
    servo: Callable[[ServoHead], S],
    measure: Callable[[ServoHead, S, Target, HeadKnowledge], Measurement],
) -> list[MeasurementRecord]:
    """Each target measured once per pass (what the head knows, its label), in target order.

    ``knowledge`` is what the phase reports the head knows; ``servo`` builds the one
    servo every measurement shares (its gains carry over); ``measure`` measures a target.
    """
    records = []
    with head(hub, "default", scenario) as sim:
        targets = scenario.scene.targets
        truth = {t.name: np.array(t.position_world_m) for t in targets}
        hub.emit(PhaseStarted("measurement", sim.truth, knowledge, truth))
        shared = servo(sim)
        for placement in targets:
            for known, known_label in passes:
                step = hub.begin(placement.name)
                sim.truth.set_body_pose(placement.body, np.array(placement.position_world_m))
                target = marker_target(placement.name, placement.body)
                m = measure(sim, shared, target, known)
                records.append(record_measurement(hub, m, known_label, step))
    return records


__all__ = ["measure_each_target"]
