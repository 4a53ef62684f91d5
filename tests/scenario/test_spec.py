"""The checked scenario's types (scenario/spec.py): moving targets, fixation counts, constants."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from headsim.procedures.contract import get, names
from headsim.scenario.spec import (
    MARKER_BODIES,
    CalibrationSpec,
    ExperimentSpec,
    MovingTarget,
    Placement,
    Scenario,
    SceneSpec,
    corner_count,
)
from headsim.sim import names as scenes
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim


def test_a_moving_target_is_piecewise_linear_at_equal_times() -> None:
    moving = MovingTarget(
        "red", "marker_red", ((0.0, 0.8, 0.2), (0.2, 0.8, 0.2), (0.2, 1.0, 0.4)), 2.0, 5
    )
    np.testing.assert_array_equal(moving.times_s, [0.0, 0.5, 1.0, 1.5, 2.0])
    np.testing.assert_allclose(moving.position(0.5), [0.1, 0.8, 0.2], atol=1e-15)
    np.testing.assert_allclose(moving.position(1.5), [0.2, 0.9, 0.3], atol=1e-15)
    np.testing.assert_array_equal(moving.position(9.0), [0.2, 1.0, 0.4])
    np.testing.assert_array_equal(replace(moving, steps=1).times_s, [0.0])


def _scenario(procedure: str, scene: SceneSpec, calibration: CalibrationSpec | None) -> Scenario:
    return Scenario(
        "case", Path("case.toml"), "a test", 0, False, "paper", HeadSettings(), "fixed",
        scene, ExperimentSpec(procedure, calibration),
    )  # fmt: skip


def test_the_fixation_count_is_the_calibrations_plus_the_procedures() -> None:
    targets = tuple(Placement(f"t{i}", "marker_red", (0.0, 0.8, 0.2), "x") for i in range(3))
    calibration = CalibrationSpec(targets=10)
    scene = SceneSpec("default", targets=targets)
    assert _scenario("model2", scene, None).fixations == 3
    assert _scenario("model2", scene, calibration).fixations == 13
    assert _scenario("calibration", scene, calibration).fixations == 16  # twice per check target
    moving = MovingTarget("red", "marker_red", ((0, 0, 0), (1, 0, 0)), 1.0, 7)
    assert _scenario("tracking", replace(scene, moving=moving), None).fixations == 7
    board = SceneSpec("chessboard")
    assert _scenario("chessboard", board, None).fixations == corner_count() == 48
    assert _scenario("chessboard", replace(board, corners=(0, 5)), None).fixations == 2
    assert _scenario("relative_positioning", SceneSpec("blocks"), calibration).fixations == 11


@pytest.mark.parametrize("preset", ["ideal", "paper", "realistic"])
def test_only_the_papers_cameras_show_the_papers_figures(preset: str) -> None:
    scenario = replace(_scenario("model2", SceneSpec("default"), None), preset=preset)
    assert scenario.paper_cameras == (preset != "ideal")


def test_every_procedure_has_a_scene_and_every_marker_body_is_in_the_default_scene() -> None:
    assert {get(name).scene for name in names()} <= set(scenes.SCENES)
    with HeadSim("default") as sim:
        for body in MARKER_BODIES:
            assert np.isfinite(sim.position(body)).all()
    assert MARKER_BODIES[scenes.CALIBRATION_BALL] == "yellow"
