"""The typed results' own logic: what "ok" means and the status text results.json shows."""

from __future__ import annotations

from dataclasses import FrozenInstanceError, replace

import pytest

from headsim.active.calibration_report import CalibrationReport, PositionOutcome
from headsim.active.failure import Failure, FailureCause
from headsim.estimators.result import Status
from headsim.runs.outcomes import RunRenders
from headsim.runs.result import RunResult
from headsim.scenario.loading import load_scenario
from headsim.sim.events import RenderCounts


def test_a_report_is_ok_only_with_status_ok_and_names_why_not() -> None:
    failed = CalibrationReport(
        Status.FAILED, "failed: degenerate layout", 4, 1, RenderCounts(images=12)
    )
    assert not failed.ok and failed.status_text == "failed: degenerate layout"
    ok = replace(failed, status=Status.OK, detail="")
    assert ok.ok and ok.status_text == "ok"
    with pytest.raises(FrozenInstanceError):
        ok.fixated = 4  # type: ignore[misc]


def test_a_position_is_ok_without_a_failure() -> None:
    cut = Failure(FailureCause.CUT, "step 2", 1, "after 2 moves")
    assert PositionOutcome(None).status == "ok"
    assert PositionOutcome(cut).status == "Ca1 at step 2: target cut (after 2 moves)"


def test_a_run_is_ok_without_failures() -> None:
    scenario = load_scenario("quickstart", fast=True)
    result = RunResult(scenario, None, (), None, RunRenders(RenderCounts(), RenderCounts(), 0), ())
    assert result.ok
    assert not replace(result, failures=("near: Ca2 at step 1: target lost",)).ok
