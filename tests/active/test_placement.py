"""Placement of calibration targets (active/placement.py): seeded, in view, in range, bounded."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.placement import calibration_layout
from headsim.sim.simulator import HeadSim


@pytest.fixture(scope="module")
def sim():
    with HeadSim("default") as sim:
        yield sim


def test_a_point_straight_ahead_is_seen_and_one_behind_or_aside_is_not(sim) -> None:
    ahead, behind, aside = (
        sim.transform_points(np.array([p]), "head", "world")[0]
        for p in ([0.0, 0.0, 0.5], [0.0, 0.0, -0.5], [2.0, 0.0, 0.5])
    )
    assert sim.stereo_view().sees_whole(np.array([ahead, behind, aside])).tolist() == [
        True,
        False,
        False,
    ]
    # A ball too big to image whole at 5 cm is not seen whole.
    near = sim.transform_points(np.array([[0.0, 0.0, 0.05]]), "head", "world")
    assert not sim.stereo_view().sees_whole(near, radius_m=0.05)[0]


def test_the_layout_is_seeded_in_view_and_in_its_depth_range(sim) -> None:
    first = calibration_layout(sim.stereo_views(), np.random.default_rng(7), 20)
    again = calibration_layout(sim.stereo_views(), np.random.default_rng(7), 20)
    other = calibration_layout(sim.stereo_views(), np.random.default_rng(8), 20)
    np.testing.assert_array_equal(first, again)
    assert not np.allclose(first, other)
    assert first.shape == (20, 3) and sim.stereo_view().sees_whole(first, 0.008).all()
    depth = sim.transform_points(first, "world", "head")[:, 2]
    assert depth.min() >= 0.25 and depth.max() <= 0.6


def test_given_depths_are_kept_and_bad_requests_are_refused(sim) -> None:
    depths = np.linspace(0.3, 0.5, 6)
    points = calibration_layout(sim.stereo_views(), np.random.default_rng(1), 6, depths_m=depths)
    np.testing.assert_allclose(sim.transform_points(points, "world", "head")[:, 2], depths)
    with pytest.raises(ValueError, match=r"depths_m must have shape \(6,\)"):
        calibration_layout(sim.stereo_views(), np.random.default_rng(1), 6, depths_m=depths[:5])
    with pytest.raises(ValueError, match="after 500 draws"):
        # At 2-3 cm a 8 mm ball spans more than the image: no position can be seen whole.
        calibration_layout(
            sim.stereo_views(), np.random.default_rng(1), 4, depth_range_m=(0.02, 0.03)
        )


def test_views_with_the_eyes_turned_differ_and_the_eyes_go_back(sim) -> None:
    before = sim.eye_encoder_steps()
    here, turned = sim.stereo_views((0.2,))
    assert sim.eye_encoder_steps() == before
    assert np.array_equal(here.world_from_head, turned.world_from_head)  # the neck stays
    assert not np.allclose(here.camera_from_world[0], turned.camera_from_world[0])
    assert np.array_equal(sim.stereo_view().camera_from_world[1], here.camera_from_world[1])
    with pytest.raises(ValueError, match="views must hold at least the current pose"):
        calibration_layout((), np.random.default_rng(1), 4)
