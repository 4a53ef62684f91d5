"""The one target sampler draws exactly what the layouts drew before it (same calls, same order)."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.geometry.sampling import sample_points_head


def test_drawn_depth_then_slopes_match_the_written_out_draws() -> None:
    points = sample_points_head(
        np.random.default_rng([7, 2]), 50, (-0.12, 0.12), (-0.06, 0.06), depth_range_m=(0.5, 1.2)
    )
    rng = np.random.default_rng([7, 2])
    z = rng.uniform(0.5, 1.2, size=50)
    expected = np.column_stack(
        [rng.uniform(-0.12, 0.12, 50) * z, rng.uniform(-0.06, 0.06, 50) * z, z]
    )
    assert points.tobytes() == expected.tobytes()
    assert np.all((points[:, 2] >= 0.5) & (points[:, 2] < 1.2))
    assert np.all(np.abs(points[:, 0] / points[:, 2]) <= 0.12 + 1e-15)


def test_given_depths_draw_no_depth_and_centre_shifts_the_slope() -> None:
    depths = np.full(20, 0.9)
    points = sample_points_head(
        np.random.default_rng(3),
        20,
        (-0.06, 0.06),
        (-0.05, 0.05),
        depths_m=depths,
        lateral_centre=0.1,
    )
    rng = np.random.default_rng(3)
    expected = np.column_stack(
        [(0.1 + rng.uniform(-0.06, 0.06, 20)) * 0.9, rng.uniform(-0.05, 0.05, 20) * 0.9, depths]
    )
    assert points.tobytes() == expected.tobytes()


def test_exactly_one_depth_source() -> None:
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="exactly one"):
        sample_points_head(rng, 3, (-0.1, 0.1), (-0.1, 0.1))
    with pytest.raises(ValueError, match="exactly one"):
        sample_points_head(
            rng, 3, (-0.1, 0.1), (-0.1, 0.1), depth_range_m=(0.5, 1.0), depths_m=np.ones(3)
        )
