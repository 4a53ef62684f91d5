"""Target sampling in H: the samples stay inside both cameras' vertical view."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.sim.settings import HeadSettings, paper_head
from headsim.studies.targets import random_targets_head, visible_vertical_range


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
