"""What Model 2, Model 1, the one-step fixation and the calibration procedure share: one
servo measuring each of the scenario's targets in turn, in the default scene."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

import numpy as np

from headsim.active.events import PhaseStarted
from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.head.servo_head import ServoHead
from headsim.runs.context import head, record_measurement
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord, SurfaceResult
from headsim.runs.surface import measure_surface_targets
from headsim.runs.targets import marker_target
from headsim.scenario.spec import Scenario

S = TypeVar("S")
R = TypeVar("R", bound=SurfaceResult)


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


def measure_targets(
    scenario: Scenario,
    hub: Hub,
    knowledge: HeadKnowledge,
    label: str,
    servo: Callable[[ServoHead], S],
    measure: Callable[[ServoHead, S, Target, HeadKnowledge], Measurement],
    result: type[R],
    both_views: bool = False,
) -> tuple[list[MeasurementRecord], R]:
    """Each target once through one shared ``servo``: ``[scene.room] targets``, where the
    scene has them (:func:`~headsim.runs.surface.measure_surface_targets`, their draw in
    ``result``), else the marker targets (:func:`measure_each_target`, ``result`` empty)."""
    if scenario.scene.surface_targets is not None:
        scored, drawn = measure_surface_targets(
            scenario, hub, knowledge, label, servo, measure, both_views
        )
        return scored, result.of(drawn)
    records = measure_each_target(scenario, hub, knowledge, [(knowledge, label)], servo, measure)
    return records, result()


__all__ = ["measure_each_target", "measure_targets"]
