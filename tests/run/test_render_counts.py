"""One render count: every image the simulator draws (whole frames, windows, retakes and
previews) is a render, counted alike in the calibration, the experiment and each
measurement, so that the measurements' renders add up to the experiment's, exactly."""

from __future__ import annotations

import pytest

from headsim.active.events import PhaseStarted
from headsim.runs.events import Stamp
from headsim.runs.result import RunResult
from headsim.runs.runner import run_scenario
from headsim.runs.serialise import results_payload
from headsim.scenario.loading import load_scenario
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.simulator import HeadSim


class Phases:
    """A subscriber that counts the images of each phase by kind and keeps its simulator."""

    def __init__(self) -> None:
        self.sims: dict[str, HeadSim] = {}
        self.kinds: dict[str, list[ImageKind]] = {}
        self._phase = ""

    def notify(self, event: object, at: Stamp) -> None:
        if isinstance(event, PhaseStarted):
            self._phase = event.name
            self.sims[event.name] = event.sim
            self.kinds[event.name] = []
        elif isinstance(event, ImageTaken):
            self.kinds[self._phase].append(event.kind)


def _run(name: str) -> tuple[RunResult, Phases]:
    phases = Phases()
    result = run_scenario(load_scenario(name, fast=True), [phases])
    assert result.ok, result.failures
    return result, phases


@pytest.fixture(scope="module")
def quickstart() -> tuple[RunResult, Phases]:
    return _run("quickstart")


@pytest.fixture(scope="module")
def relative() -> tuple[RunResult, Phases]:
    return _run("relative_positioning")


def _check_phases(result: RunResult, phases: Phases) -> None:
    """Each phase's counts are its images by kind, and its simulator's ``render_count``
    (what each measurement's ``renders`` is taken from); overall is their sum."""
    renders = result.renders
    for name, counts in (("calibration", renders.calibration), ("measurement", renders.experiment)):
        kinds = phases.kinds[name]
        assert counts.images == kinds.count(ImageKind.FULL)
        assert counts.windows == kinds.count(ImageKind.WINDOW)
        assert counts.retakes == kinds.count(ImageKind.RETAKE)
        assert counts.previews == kinds.count(ImageKind.PREVIEW)
        assert counts.total == len(kinds) == phases.sims[name].render_count
    assert renders.overall == renders.calibration + renders.experiment
    assert result.calibration is not None and result.calibration.renders == renders.calibration


def test_the_quick_starts_measurements_add_up_to_its_experiment(
    quickstart: tuple[RunResult, Phases],
) -> None:
    result, phases = quickstart
    _check_phases(result, phases)
    renders = result.renders
    assert renders.calibration.previews > 0 and renders.experiment.previews > 0
    # Model 2's measurements are the whole experiment: nothing outside them.
    assert sum(r.measurement.renders for r in result.records) == renders.experiment.total
    assert renders.outside_measurements == 0
    payload = results_payload(result)
    counts = payload["render_counts"]
    experiment = counts["experiment"]
    assert experiment["total"] == experiment["in_measurements"] == renders.experiment.total
    assert experiment["previews"] == renders.experiment.previews > 0
    assert counts["overall"]["total"] == (
        counts["calibration"]["total"] + counts["experiment"]["total"]
    )
    assert counts["calibration"] == payload["calibration"]["render_counts"]


def test_relative_positionings_area_images_are_its_own_entry(
    relative: tuple[RunResult, Phases],
) -> None:
    result, phases = relative
    _check_phases(result, phases)
    renders = result.renders
    assert renders.calibration.previews > 0  # the cross point is found in whole frames
    # The cross point's measurement, then the four images of the objects (each camera
    # at each fixation) that belong to no measurement.
    (record,) = result.records
    assert renders.in_measurements == record.measurement.renders
    assert renders.outside_measurements == 4
    assert record.measurement.renders + 4 == renders.experiment.total
    experiment = results_payload(result)["render_counts"]["experiment"]
    assert (
        experiment["in_measurements"] + experiment["outside_measurements"] == (experiment["total"])
    )
