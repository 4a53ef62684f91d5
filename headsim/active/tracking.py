"""A moving target followed with Model 1: one fixation per time, the servo's image
Jacobian carried from one to the next.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from headsim.active.events import FixationStarted, MeasurementDone
from headsim.active.measurement import (
    HeadKnowledge,
    Measurement,
    Target,
)
from headsim.active.model1 import measure_model1
from headsim.active.neck_servo import NeckServo
from headsim.sim.events import EventSink
from headsim.sim.simulator import HeadSim


@dataclass(frozen=True)
class TrackingRun:
    """A moving target followed with the neck model: one measurement per fixation, time in s."""

    times_s: np.ndarray
    measurements: tuple[Measurement, ...]

    @property
    def errors_world_m(self) -> np.ndarray:
        """(N,) 3-D error of each fixation in W, m (NaN where it failed)."""
        return np.array(
            [np.linalg.norm(m.estimate_world_m - m.truth_world_m) for m in self.measurements]
        )


def track_moving_target(
    sim: HeadSim,
    servo: NeckServo,
    target: Target,
    body: str,
    trajectory: Callable[[float], np.ndarray],
    times_s: Sequence[float],
    knowledge: HeadKnowledge | None = None,
    sink: EventSink | None = None,
) -> TrackingRun:
    """Move ``body`` along ``trajectory(t)`` (world, m) and fixate it at each time with Model 1.

    The servo's Jacobian carries from one fixation to the next, so after the
    first fixation each one starts from the last and takes few renders.  A
    target that left both views since is searched for around the last
    fixation (:func:`headsim.active.search.find_neck_view`), then from the start pose.
    ``sink``: where each fixation ("<target> 1", ...) and measurement is reported
    (None: the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    measurements = []
    fixations: list[tuple[int, int, int]] = []  # where the target was seen, in steps
    for k, t in enumerate(times_s):
        sink.emit(FixationStarted(f"{target.name} {k + 1}"))
        sim.set_body_pose(body, trajectory(float(t)))
        m = measure_model1(sim, servo, target, knowledge, last_seen=fixations[-2:])
        sink.emit(MeasurementDone(m, float(t)))
        measurements.append(m)
        if m.ok:
            fixations.append(servo.steps())
    return TrackingRun(np.asarray(times_s, dtype=float), tuple(measurements))


__all__ = ["TrackingRun", "track_moving_target"]
