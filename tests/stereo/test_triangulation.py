"""Triangulation and stereo measurement of rendered markers (real MuJoCo, no mocks)."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.head.sim_head import SimHead
from headsim.sim import names
from headsim.sim.settings import ideal_head, paper_head
from headsim.sim.simulator import HeadSim
from headsim.stereo.triangulation import measure_point_stereo, triangulate
from headsim.stereo.views import StereoError

from .conftest import PRESETS
from .helpers import calibration_from_truth


@pytest.mark.render
def test_stereo_error_at_a_known_depth_is_below_half_a_percent(calibrated) -> None:
    name, _, calib = calibrated
    settings = PRESETS[name]()
    with HeadSim("default", settings) as sim:
        sim.move(eye=0.0)
        world_from_head = sim.world_from_head()
        for p_head in ([0.0, 0.0, 0.8], [0.06, -0.04, 0.6]):
            p_world = world_from_head[:3, :3] @ p_head + world_from_head[:3, 3]
            sim.set_body_pose(names.MARKERS[0], p_world)
            measured = measure_point_stereo(SimHead(sim), calib, names.MARKERS[0])
            np.testing.assert_allclose(measured.true_p_head, p_head, atol=1e-12)
            assert measured.error_rel_depth < 0.005, (name, p_head, measured.error_m)
            assert abs(measured.error_m[2]) < 0.005 * p_head[2]


@pytest.mark.render
def test_a_target_that_is_not_seen_is_a_clear_error(calibrated) -> None:
    _, _, calib = calibrated
    with HeadSim("default", ideal_head()) as sim:
        sim.set_body_pose(names.MARKERS[0], [0.0, -1.0, 0.2])  # behind the head
        with pytest.raises(StereoError, match="'marker_red' not found in cam1: lost"):
            measure_point_stereo(SimHead(sim), calib, names.MARKERS[0])


def test_triangulation_with_the_true_calibration_recovers_points_exactly(rng) -> None:
    # Strong barrel distortion out to the image corners: the undistortion must converge.
    with HeadSim("default", paper_head()) as sim:
        calib = calibration_from_truth(sim)
        p_head = np.column_stack(
            [rng.uniform(-0.15, 0.15, 200), rng.uniform(-0.1, 0.1, 200), rng.uniform(0.4, 1.5, 200)]
        )
        p_world = sim.transform_points(p_head, "head", "world")
        uv1, uv2 = sim.project(p_world, 1), sim.project(p_world, 2)
        inside = np.all((uv1 > 0) & (uv1 < [639, 479]) & (uv2 > 0) & (uv2 < [639, 479]), axis=1)
        assert inside.sum() > 100
        estimate = triangulate(calib, uv1[inside], uv2[inside])
    np.testing.assert_allclose(estimate, p_head[inside], atol=1e-7)
