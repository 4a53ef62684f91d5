"""The Sec. V calibration phase: its report, from a rendered run of the quick start."""

from __future__ import annotations

from headsim.active.failure import Failure, FailureCause
from headsim.estimators.result import Status
from headsim.run.phases.calibrate import position_outcomes
from headsim.run.runner import calibrate_scenario
from headsim.scenario.loading import load_scenario


def test_the_quick_start_calibrates_within_its_stated_errors() -> None:
    scenario = load_scenario("quickstart", fast=True)
    spec = scenario.experiment.calibration
    assert spec is not None
    report = calibrate_scenario(scenario)
    assert report.status is Status.OK and report.status_text == "ok"
    assert report.fixated == len(report.positions) == spec.targets
    assert all(p.failure is None and p.status_text == "ok" for p in report.positions)
    assert report.layout is not None and len(report.layout.positions_world_m) == spec.targets
    assert report.rendered_frames is not None and report.rendered_frames > 0
    assert report.knowledge is not None and report.knowledge.alpha_e_rad is not None
    errors, stds = report.alpha_e_error_rad, report.alpha_e_std_rad
    assert errors is not None and stds is not None
    # A tape measure: within four of the fit's stated standard errors.
    assert all(abs(e) < 4 * s for e, s in zip(errors, stds, strict=True))


def test_each_position_outcome_keeps_its_failure() -> None:
    lost = Failure(FailureCause.LOST, "step 1", 2)
    outcomes = position_outcomes([None, lost])
    assert [o.failure for o in outcomes] == [None, lost]
    assert [o.status_text for o in outcomes] == ["ok", "Ca2 at step 1: target lost"]
