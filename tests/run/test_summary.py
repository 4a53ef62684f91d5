"""The summary table, from typed results: columns padded, a failed calibration named."""

from __future__ import annotations

from headsim.active.calibration_report import CalibrationReport
from headsim.estimators.result import Status
from headsim.runs.outcomes import RunRenders
from headsim.runs.result import RunResult
from headsim.runs.summary import format_table, summary_text
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
    report = CalibrationReport(Status.FAILED, "failed: too few positions seen", 8, 2, counts)
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


def test_the_headline_gives_measured_of_accepted_and_of_drawn_and_the_edge_apart() -> None:
    from dataclasses import replace

    from headsim.runs.outcomes import MeasurementRecord

    from .helpers import LOST, measurement

    scenario = load_scenario("stress_zoom", fast=True, seed=1)
    a = scenario.scene.acceptance
    assert a is not None and a.refused and a.outside_start_view
    edge = set(a.outside_start_view)
    records = []
    for k, t in enumerate(scenario.scene.targets):
        # the edge ones 1 % off, the others 0.1 %; the first target failed
        m = measurement((0.01 if t.name in edge else 0.001) * 0.8, 0.8, LOST if k == 0 else None)
        scan = 3 if t.name in edge else 0  # a scan's renders are a search's
        m = replace(m, name=t.name, scan_renders=scan, search_renders=scan)
        records.append(MeasurementRecord(m, "calibrated", k))
    result = RunResult(
        scenario,
        None,
        tuple(records),
        None,
        RunRenders(RenderCounts(), RenderCounts(), 0),
        ("failed",),
    )
    text = summary_text(result)
    ok = len(records) - 1
    refused = ", ".join(f"{n} {code}" for code, n in a.refused.items())
    assert (
        f"    {ok} of {a.accepted} accepted targets measured, {ok} of "
        f"{a.drawn} drawn ({a.refused_total} draws refused by the reach check and drawn again: "
        f"{refused})"
    ) in text
    edge_ok = len(edge - {scenario.scene.targets[0].name})
    assert text.count("head knew calibrated:") == 1
    assert f"whole field, the {ok} of {len(records)} measured (drawn over it):" in text
    assert (
        "of them at the edge of the field (not seen whole by both cameras at the start pose): "
        f"{edge_ok} of {len(edge)} measured, 3-D error RMS 1.000 % of depth"
    ) in text
    assert (
        f"{len(edge)} targets searched for again, {3 * len(edge)} renders of search ({len(edge)} "
        f"scanned for where the head's pose did not show them: {3 * len(edge)} renders, 3.0 per "
        "target)"
    ) in text
