"""The figures the benchmarks print: pure summaries checked on known inputs."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.measurement import Measurement
from headsim.estimators.result import Method, Status
from headsim.sim.settings import HeadSettings, paper_head
from headsim.studies.experiments import error_figures, random_targets_head, visible_vertical_range


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


def test_targets_stay_inside_both_cameras_vertical_view() -> None:
    low, high = visible_vertical_range(paper_head())
    # Camera 2's principal row is 197.3 of 480: it sees less upwards than camera 1.
    assert low == pytest.approx(-0.85 * 197.3 / 833.29)
    assert high == pytest.approx(0.85 * (479 - 306.3) / 815.42)
    ideal_low, ideal_high = visible_vertical_range(HeadSettings())
    assert ideal_low == pytest.approx(-ideal_high)
    points = random_targets_head(np.random.default_rng(0), 500, (0.3, 1.5), vertical=(low, high))
    ratios = points[:, 1] / points[:, 2]
    assert ratios.min() >= low and ratios.max() <= high
    assert points[:, 2].min() >= 0.3 and points[:, 2].max() <= 1.5
