"""Tracking a moving target with Model 1, one fixation per time."""

from __future__ import annotations

from collections.abc import Callable

from headsim.procedures.tracking import TrackingResult
from headsim.runs.result import RunResult


def test_every_fixation_is_within_3_mm(fast_run: Callable[[str], RunResult]) -> None:
    result = fast_run("tracking")
    assert result.ok, result.failures
    e = result.experiment
    moving = result.scenario.scene.moving
    assert isinstance(e, TrackingResult) and moving is not None
    assert len(e.errors_world_m) == moving.steps == len(result.records)
    assert max(e.errors_world_m) < 0.003
    assert [r.time_s for r in result.records] == [float(t) for t in e.times_s]
