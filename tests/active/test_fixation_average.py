"""Which whole steps an averaged fixation looks at (pure arithmetic)."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.eye_servo import pixel_period_steps


@pytest.mark.parametrize("gain", [0.05, 0.1, 0.143, -0.204, 0.265, 0.326, -0.41, 0.6])
def test_averaged_steps_spread_evenly_over_one_pixel(gain: float) -> None:
    steps = pixel_period_steps(100.3, gain, most=8)
    stride = steps[1] - steps[0]
    assert 2 <= len(steps) <= 8 and np.all(np.diff(steps) == stride)
    # One pixel of image motion, to within one stride's (whole steps), around the centre.
    assert abs(len(steps) * stride * abs(gain) - 1.0) <= max(0.5, stride * abs(gain)) / 2 + 1e-9
    assert abs(np.mean(steps) - 100.3) <= 0.5 + 1e-9


def test_a_pixel_of_many_steps_is_sampled_every_kth_step() -> None:
    # 0.05 px per step: 20 steps to a pixel, at most 8 images: every 3rd step, 7 of them.
    steps = pixel_period_steps(0.0, 0.05, most=8)
    assert np.all(np.diff(steps) == 3) and len(steps) == 7
    # A pixel of fewer than two steps still takes two images.
    assert len(pixel_period_steps(0.0, 0.9, most=8)) == 2
