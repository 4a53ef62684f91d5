"""The realistic head's error budget (headsim.studies.error_budget): rendered runs, files, first-order check."""

from __future__ import annotations

import csv
import json

import cv2

from headsim import cli
from headsim.studies import error_budget
from headsim.studies.error_budget import BudgetCondition, run_condition


def test_study_budget_fast_writes_the_table_and_the_chart(tmp_path) -> None:
    out = tmp_path / "study"
    code = cli.main(["--quiet", "study", "--experiment", "budget", "--fast", "--out", str(out)])
    assert code == 0
    with open(out / "error_budget.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["condition"] for r in rows] == list(error_budget.FAST_CONDITIONS)
    assert all(r["measured"] == r["targets"] == "4" for r in rows)
    by_name = {r["condition"]: r for r in rows}
    everything = float(by_name["realistic, everything on"]["rms_3d_pct"])
    sec5 = float(by_name["Sec. V only (no v0, kx/ky, offsets)"]["rms_3d_pct"])
    assert 0 < everything < 0.5  # the realistic headline's order, on 4 targets
    assert sec5 > 3 * everything  # without the v0 fit the rows' y is off (Table VI)
    for r in rows:  # the paper's analysis beside every row, finite
        assert 0 < float(r["predicted_xz_pct"]) < 5
    table = (out / "error_budget.md").read_text()
    assert "| realistic, everything on | 4/4 |" in table and "eqs. 17/19" in table
    assert len(json.loads((out / "error_budget.json").read_text())["rows"]) == len(rows)
    image = cv2.imread(str(out / "error_budget.png"))
    assert image is not None and image.shape[0] > 200 and image.shape[1] > 400


def test_uncorrected_offsets_cost_what_the_first_order_analysis_says() -> None:
    """3 mm / -3 mm side offsets (an effective baseline 6 mm short), rendered, 4 targets."""
    big = {"cam1.side_offset_m": 0.003, "cam2.side_offset_m": -0.003}
    off = {"cam1.side_offset_m": 0.0, "cam2.side_offset_m": 0.0}
    off |= {"cam1.nodal_offset_m": 0.0, "cam2.nodal_offset_m": 0.0}
    no_fit = {"experiment.calibration.lines_of_sight": False}
    uncorrected = run_condition(BudgetCondition("big", "test", big | no_fit), fast=True, seed=0)
    without = run_condition(BudgetCondition("off", "test", off | no_fit), fast=True, seed=0)
    fitted = run_condition(BudgetCondition("fitted", "test", big), fast=True, seed=0)
    assert uncorrected["measured"] == without["measured"] == fitted["measured"] == 4
    # Switching the offsets off, still uncorrected, lowers the error; fitting them does too.
    assert uncorrected["rms_xz_pct"] > 2 * without["rms_xz_pct"]
    assert fitted["rms_3d_pct"] < uncorrected["rms_3d_pct"] / 3
    # Eqs. 17/19 with Sec. V's fit absorbing part of the bias: within 20 %.
    ratio = uncorrected["rms_xz_pct"] / uncorrected["predicted_xz_pct"]
    assert 0.8 < ratio < 1.2, ratio
    assert abs(fitted["effective_baseline_error_mm"]) < 0.5
