"""The results in the recording: truth and estimates at each measurement step, the text documents."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from headsim.active.calibration_report import CalibrationReport
from headsim.estimators.result import Status
from headsim.run.recording_results import calibration_markdown
from headsim.sim.events import RenderCounts

from .rrd import rows


def test_true_and_estimated_points_at_each_measurement_step(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    measurements = results["measurements"]
    estimates = rows(rrd, "/world/estimate", "Points3D:positions")
    assert [r["step"] for r in estimates] == [m["step"] for m in measurements]
    # The last row holds every estimate, where results.json has them.
    np.testing.assert_allclose(
        np.array(estimates[-1]["value"]), [m["estimate_world_m"] for m in measurements], atol=1e-6
    )
    truth = rows(rrd, "/world/truth", "Points3D:positions")
    np.testing.assert_allclose(
        np.array(truth[-1]["value"]), [m["truth_world_m"] for m in measurements], atol=1e-6
    )
    errors = rows(rrd, "/measurements/error_mm", "Scalars:scalars")
    assert [r["step"] for r in errors] == [m["step"] for m in measurements]
    np.testing.assert_allclose(
        [r["value"][0] for r in errors], [1000 * m["error_m"] for m in measurements], rtol=1e-6
    )
    calibration = rows(rrd, "/world/calibration/positions", "Points3D:positions")
    assert len(calibration[0]["value"]) == results["calibration"]["targets"]
    steps = {r["step"] for r in rows(rrd, "/world/current_target", "Points3D:positions")}
    assert steps == set(range(results["calibration"]["targets"] + len(measurements)))


def test_results_are_in_the_recording_as_text(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    summary = rows(rrd, "/results/summary", "TextDocument:text")
    assert "OK: 3 measurements, none failed" in summary[-1]["value"][0]
    calibration = rows(rrd, "/results/calibration", "TextDocument:text")
    text = calibration[-1]["value"][0]
    assert f"{results['calibration']['alpha_e_rad'][0]:.5f}" in text and "0.0578" in text


def test_the_calibration_document_reads_the_report() -> None:
    failed = CalibrationReport(
        Status.FAILED, "failed: too few positions seen", 8, 2, RenderCounts(images=30), ()
    )
    assert calibration_markdown(failed) == "# Calibration\n\nfailed: too few positions seen\n"
    ok = replace(
        failed,
        status=Status.OK,
        detail="",
        fixated=8,
        alpha_e_rad=[0.05812, -0.02531],
        alpha_e_truth_rad=[0.0578, -0.0254],
        alpha_e_paper_rad=[0.0578, -0.0254],
    )
    text = calibration_markdown(ok)
    assert "8 of 8 positions fixated, 30 renders" in text
    assert "| alpha_e1 | 0.05812 | 0.05780 | 0.0578 |" in text and "extended" not in text
