"""``[experiment.calibration] positions_world_m``: ball positions given instead of drawn."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from headsim.run.runner import run_scenario
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
