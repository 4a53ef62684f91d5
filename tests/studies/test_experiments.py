"""The figures the benchmarks print: pure summaries checked on known inputs."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.measurement import Measurement
from headsim.estimators.result import Method, Status
from headsim.studies.experiments import error_figures


def _measurement(error_m, depth_m: float, status: str = "ok") -> Measurement:
    truth = np.array([0.0, 0.0, depth_m])
    return Measurement(
        name="t",
        method=Method.MODEL2,
        status=Status.OK if status == "ok" else Status.FAILED,
        detail="" if status == "ok" else status,
        estimate_head_m=truth + np.asarray(error_m, float),
        truth_head_m=truth,
        estimate_world_m=truth,
        truth_world_m=truth,
        covariance_head_m2=np.eye(3),
        renders=7,
        servo_residual_px=(0.0, 0.0),
    )


def test_error_figures_are_rms_in_mm_and_percent_of_depth() -> None:
    ms = [
        _measurement([0.003, 0, 0.004], 1.0),
        _measurement([0, 0, 0], 0.5),
        _measurement([1, 1, 1], 1.0, "lost"),
    ]
    f = error_figures(ms)
    assert f["count"] == 2 and f["failed"] == 1
    assert f["rms_3d_mm"] == pytest.approx(np.sqrt((5.0**2 + 0.0) / 2))
    assert f["rms_3d_pct_depth"] == pytest.approx(np.sqrt((0.5**2) / 2))
    np.testing.assert_allclose(f["rms_pct_depth_xyz"], [0.3 / np.sqrt(2), 0, 0.4 / np.sqrt(2)])
    assert f["max_3d_pct_depth"] == pytest.approx(0.5)
    assert error_figures([ms[2]]) == {"count": 0, "failed": 1}


def test_area_tally_counts_every_object_placed_and_the_margin_subset_apart() -> None:
    """An object not seen, one near a boundary and a layout with no fixation all count."""
    from headsim.estimators.areas import compare_areas
    from headsim.studies.experiments import area_tally

    # Layout 1: 4 of 6 seen; one of them disagrees 0.5 px from a boundary (inside the
    # margin), the other three agree far from every boundary.
    far = [40.0, 60.0, -30.0, 25.0]
    near = [40.0, 0.5, -30.0, 25.0]  # u12 0.5 px from Ca1's goal column
    columns = np.array([far, far, far, near]).T
    first = compare_areas([5, 6, 7, 8], [5, 6, 7, 3], *columns, 0.0, 0.0)
    assert (first.n_inside, first.n_disagree_inside) == (1, 1)
    # Layout 2: all six seen and right.  Layout 3: the reference was not fixated.
    columns2 = np.array([far] * 6).T
    second = compare_areas([5] * 6, [5] * 6, *columns2, 0.0, 0.0)
    tally = area_tally(6, [(2, first), (0, second), (1, None)])
    assert tally["objects"] == 18
    assert tally["correct"] == 3 + 6
    assert tally["correct_pct"] == pytest.approx(100 * 9 / 18)
    assert tally["not_seen_in_all_four_images"] == 3
    assert tally["reference_not_fixated"] == 5
    assert tally["outside_margin"] == 9
    assert tally["outside_margin_correct_pct"] == pytest.approx(100.0)
    assert (tally["within_2px_of_a_boundary"], tally["within_2px_disagreeing"]) == (1, 1)


def test_the_tracking_scenario_puts_the_target_on_the_circle_at_every_fixation() -> None:
    from headsim.studies.experiments import _circle_world_m, tracking_scenario

    scenario = tracking_scenario(7)
    moving = scenario.scene.moving
    assert scenario.experiment.procedure == "tracking" and moving is not None
    assert scenario.fixations == 7 and scenario.experiment.calibration is None
    for t in moving.times_s:
        assert np.array_equal(moving.position(float(t)), _circle_world_m(float(t)))


def test_tracking_through_the_runner_fixates_every_time_within_a_millimetre() -> None:
    from headsim.studies.experiments import tracking_accuracy

    figures = tracking_accuracy(fixations=3)
    assert figures["fixations"] == 3 and figures["ok"] == 3
    assert 0.0 < figures["error_world_mm_rms"] <= figures["error_world_mm_max"] < 1.0
    assert figures["renders_first"] > figures["renders_per_fixation_after_first"] > 0


def test_a_target_a_scenario_would_refuse_is_not_reachable() -> None:
    from headsim.sim.settings import paper_head
    from headsim.studies.experiments import reachable

    # Behind the green marker, for camera 1; then one straight ahead.
    targets = [np.array([-0.087, 0.003, 0.764]), np.array([0.0, 0.0, 0.8])]
    assert reachable(paper_head(), targets) == [False, True]


def test_model2_accuracy_runs_its_targets_as_a_scenario() -> None:
    from headsim.sim.settings import HeadSettings
    from headsim.studies.experiments import model2_accuracy

    figures = model2_accuracy(HeadSettings(), np.random.default_rng(0), targets_per_band=1)
    assert figures["refused_targets"] == 0
    assert figures["overall"]["count"] == 3 and figures["overall"]["failed"] == 0
    assert [f["count"] for f in figures["bands"].values()] == [1, 1, 1]
    assert figures["overall"]["rms_3d_pct_depth"] < 0.05
    assert figures["render_s"] > 0 and "calibration" not in figures
