"""The summary table, from typed results: columns padded, a failed calibration named."""

from __future__ import annotations

from headsim.estimators.result import Status
from headsim.run.outcomes import CalibrationReport, RunRenders, RunResult
from headsim.run.summary import format_table, summary_text
from headsim.scenario.loading import load_scenario
from headsim.sim.events import RenderCounts


def test_columns_are_padded_first_left_then_right() -> None:
    assert format_table(["name", "mm"], [["near", "0.88"], ["far_left", "10.5"]]) == [
        "  name        mm",
        "  near      0.88",
        "  far_left  10.5",
    ]


def test_a_failed_calibration_is_the_summarys_problem() -> None:
    scenario = load_scenario("quickstart", fast=True)
    counts = RenderCounts(images=20, windows=6, retakes=1, previews=4)
    report = CalibrationReport(Status.FAILED, "failed: too few positions seen", 8, 2, counts, ())
    result = RunResult(
        scenario=scenario,
        calibration=report,
        records=(),
        experiment=None,
        renders=RunRenders(counts, RenderCounts(), 0),
        failures=(f"calibration: {report.status_text}",),
    )
    text = summary_text(result)
    assert "; 31 renders (20 full frames, 6 windows, 1 retake, 4 previews)" in text
    assert "Calibration of the initial directions (Sec. V): 2 of 8 ball positions fixated" in text
    assert "  failed: too few positions seen" in text
    assert text.endswith("FAILED: 1 problem(s)\n  calibration: failed: too few positions seen")
