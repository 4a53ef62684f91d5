"""``[experiment.calibration] positions_world_m``: ball positions given instead of drawn."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from headsim.runs.runner import run_scenario
from headsim.scenario.loading import scenario_from_document
from headsim.scenario.spec import experiment_record
from headsim.scenario.tables import ScenarioError


def _doc(calibration: dict[str, Any]) -> dict[str, Any]:
    return {
        "description": "a calibration with few balls",
        "head": {"preset": "paper"},
        "experiment": {"procedure": "calibration", "calibration": calibration},
    }


@pytest.mark.parametrize(
    ("value", "field"),
    [
        ([[0.0, 0.0]], "positions_world_m"),
        ([[0.0, 0.0, 0.4]] * 2, "positions_world_m"),
        ([[0.0, 0.0, 0.4], [0.0, 0.0, "far"], [0.0, 0.0, 0.5]], r"positions_world_m\[1\]"),
    ],
)
def test_a_bad_position_list_names_the_key_and_what_is_allowed(value: Any, field: str) -> None:
    with pytest.raises(ScenarioError, match=rf"experiment\.calibration\.{field}.*\[x, y, z\]"):
        scenario_from_document(_doc({"positions_world_m": value}), "bad")


def test_targets_other_than_the_positions_count_is_refused() -> None:
    positions = [[0.0, 0.0, 0.4], [0.02, 0.0, 0.45], [0.0, 0.02, 0.5]]
    with pytest.raises(ScenarioError, match=r"calibration\.targets: 5 with 3 positions_world_m"):
        scenario_from_document(_doc({"positions_world_m": positions, "targets": 5}), "bad")


@pytest.mark.render
def test_given_positions_calibrate_as_the_same_positions_drawn() -> None:
    drawn = run_scenario(scenario_from_document(_doc({"targets": 6}), "drawn"))
    assert drawn.calibration is not None and drawn.calibration.layout is not None
    positions = np.asarray(drawn.calibration.layout.positions_world_m).tolist()
    scenario = scenario_from_document(_doc({"positions_world_m": positions}), "given")
    assert "positions_world_m" not in experiment_record(drawn.scenario.experiment)["calibration"]
    assert experiment_record(scenario.experiment)["calibration"]["positions_world_m"]
    given = run_scenario(scenario)
    assert given.calibration is not None and given.calibration.layout is not None
    assert given.calibration.layout.kind == "given"
    assert given.calibration.targets == 6
    assert given.calibration.alpha_e_rad == drawn.calibration.alpha_e_rad


@pytest.mark.render
def test_the_reported_truth_is_the_goal_columns_own() -> None:
    """With the servo on other columns than the image centres, the report's truth is the
    effective direction through those columns: fitted minus truth is the reported error,
    and the truth differs from the image centres' by the columns' angle."""
    doc = _doc({"targets": 6})
    centre = run_scenario(scenario_from_document(doc, "centre")).calibration
    doc["experiment"]["goal_columns_px"] = [300.0, 340.0]
    goal = run_scenario(scenario_from_document(doc, "goal")).calibration
    for report in (centre, goal):
        assert report is not None and report.alpha_e_rad is not None
        assert report.alpha_e_truth_rad is not None and report.alpha_e_error_rad is not None
        fitted_minus_truth = np.subtract(report.alpha_e_rad, report.alpha_e_truth_rad)
        np.testing.assert_allclose(fitted_minus_truth, report.alpha_e_error_rad, atol=1e-12)
    assert centre is not None and goal is not None
    assert centre.alpha_e_truth_rad is not None and goal.alpha_e_truth_rad is not None
    # 20 px off the centre is about 24 mrad at the paper head's 835 px focal length.
    assert np.all(np.abs(np.subtract(goal.alpha_e_truth_rad, centre.alpha_e_truth_rad)) > 0.01)
