"""The study's methods and configuration (studies/methods.py)."""

from __future__ import annotations

import numpy as np

from headsim.runs.progress import quiet
from headsim.sim import names
from headsim.sim.simulator import HeadSim
from headsim.studies.methods import (
    BALL,
    METHOD_LABELS,
    METHODS,
    SWEEP_METHODS,
    TARGET,
    StudyConfig,
)


def test_every_method_has_one_label_and_the_sweeps_leave_out_refinding() -> None:
    assert list(METHOD_LABELS) == list(METHODS)
    assert len(set(METHOD_LABELS.values())) == len(METHODS)
    assert set(METHODS) - set(SWEEP_METHODS) == {"active_refound"}
    assert quiet("anything") is None


def test_the_quick_config_is_smaller_in_every_count_and_takes_overrides() -> None:
    full, quick = StudyConfig(), StudyConfig.quick()
    for name in (
        "board_poses",
        "calibration_targets",
        "principal_poses",
        "targets_per_depth",
        "table_targets",
    ):
        assert 0 < getattr(quick, name) < getattr(full, name), name
    assert quick.fast and not full.fast
    assert StudyConfig.quick(seed=4, board_poses=9) == StudyConfig(
        seed=4, board_poses=9, calibration_targets=16, principal_poses=1,
        targets_per_depth=2, table_targets=3, fast=True,
    )  # fmt: skip


def test_the_targets_are_the_red_marker_and_the_ball_found_by_colour() -> None:
    assert (TARGET.name, BALL.name) == (names.MARKERS[0], names.CALIBRATION_BALL)
    with HeadSim("default") as sim:
        truth = TARGET.truth_world(sim)
        np.testing.assert_array_equal(truth, sim.position(names.MARKERS[0]))
        np.testing.assert_array_equal(BALL.truth_world(sim), sim.position(names.CALIBRATION_BALL))
        seen = TARGET.detector(sim.render(1))
        assert seen.found
        np.testing.assert_allclose(seen.uv, sim.project(truth, 1)[0], atol=0.5)
