"""The run's events reach a subscriber numbered and counted, from a real run of the quick start."""

from __future__ import annotations

import pytest

from headsim.active.events import Detected, FixationStarted, PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.neck_servo import NeckServo
from headsim.runs.events import (
    CalibrationDone,
    MeasurementRecorded,
    RunFinished,
    Stamp,
)
from headsim.runs.result import RunResult
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.simulator import HeadSim


class Collect:
    """A subscriber that keeps every event with its stamp."""

    def __init__(self) -> None:
        self.seen: list[tuple[object, Stamp]] = []

    def notify(self, event: object, at: Stamp) -> None:
        self.seen.append((event, at))

    def of(self, kind: type) -> list[tuple[object, Stamp]]:
        return [(e, at) for e, at in self.seen if isinstance(e, kind)]


@pytest.fixture(scope="module")
def run() -> tuple[RunResult, Collect]:
    collect = Collect()
    result = run_scenario(load_scenario("quickstart", fast=True), [collect])
    assert result.ok, result.failures
    return result, collect


def test_images_are_numbered_in_order_and_counted_as_the_result_counts_them(
    run: tuple[RunResult, Collect],
) -> None:
    result, collect = run
    images = collect.of(ImageTaken)
    shown = [at.frame for e, at in images if e.kind is not ImageKind.PREVIEW]  # type: ignore[attr-defined]
    assert shown == list(range(len(shown)))
    # Every image drawn is a render, the previews too.
    overall = result.renders.overall
    assert len(images) == overall.total
    kinds = [e.kind for e, _ in images]  # type: ignore[attr-defined]
    assert kinds.count(ImageKind.FULL) == overall.images > 0
    assert kinds.count(ImageKind.WINDOW) == overall.windows > 0
    assert kinds.count(ImageKind.RETAKE) == overall.retakes
    assert kinds.count(ImageKind.PREVIEW) == overall.previews > 0
    total = sum(e.rendered_frames for e, _ in images)  # type: ignore[attr-defined]
    assert total == pytest.approx(result.rendered_frames["total"], rel=1e-12)


def test_detections_are_stamped_with_the_image_they_were_made_in(
    run: tuple[RunResult, Collect],
) -> None:
    _, collect = run
    last: ImageTaken | None = None
    detections = 0
    for event, at in collect.seen:
        if isinstance(event, ImageTaken) and event.kind is not ImageKind.PREVIEW:
            last = event
        elif isinstance(event, Detected):
            detections += 1
            assert last is not None and event.camera == last.camera
            assert at.frame >= 0
    assert detections > 0


def test_phases_steps_and_measurements_in_order(run: tuple[RunResult, Collect]) -> None:
    result, collect = run
    phases = [e for e, _ in collect.of(PhaseStarted)]
    assert [p.name for p in phases] == ["calibration", "measurement"]  # type: ignore[attr-defined]
    # A plain simulator: nothing subclasses HeadSim (or a servo) to watch the run.
    assert all(type(p.sim) is HeadSim for p in phases)  # type: ignore[attr-defined]
    ours = [
        sub
        for base in (HeadSim, EyeServo, NeckServo)
        for sub in base.__subclasses__()
        if sub.__module__.startswith("headsim.")
    ]
    assert ours == []
    steps = [at.step for _, at in collect.of(FixationStarted)]
    assert steps == list(range(len(steps)))
    assert len(steps) == result.scenario.fixations
    recorded = [e.record for e, _ in collect.of(MeasurementRecorded)]  # type: ignore[attr-defined]
    assert [r.step for r in recorded] == [r.step for r in result.records]
    assert [type(e) for e, _ in collect.seen[-1:]] == [RunFinished]
    assert len(collect.of(CalibrationDone)) == 1
