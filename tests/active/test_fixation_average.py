"""The averaged fixation's pure parts: which steps, how many images, the learnt scatter."""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest

from headsim.active.fixation_average import (
    PRIOR_RESIDUALS,
    ScatterMemory,
    detector_kind,
    pixel_period_steps,
    samples_wanted,
)
from headsim.vision.markers import find_marker


@pytest.mark.parametrize("gain", [0.05, 0.1, 0.143, -0.204, 0.265, 0.326, -0.41, 0.6])
def test_averaged_steps_spread_evenly_over_one_pixel(gain: float) -> None:
    steps = pixel_period_steps(100.3, gain, most=8)
    stride = steps[1] - steps[0]
    assert 2 <= len(steps) <= 8 and np.all(np.diff(steps) == stride)
    # One pixel of image motion, to within one stride's (whole steps), around the centre.
    assert abs(len(steps) * stride * abs(gain) - 1.0) <= max(0.5, stride * abs(gain)) / 2 + 1e-9
    assert abs(np.mean(steps) - 100.3) <= 0.5 + 1e-9


def test_samples_wanted_reach_the_target_standard_error() -> None:
    # One image: 0.02 px / 0.2 px per step = 0.1 step; 0.05 step needs 4 images.
    assert samples_wanted(0.02, 0.2, 0.05) == 4
    assert samples_wanted(0.02, -0.2, 0.05) == 4
    assert samples_wanted(0.005, 0.2, 0.05) == 1  # one image is enough
    assert samples_wanted(0.02, 0.2, 0.0) == 1  # averaging off
    for sigma, gain, target in [(0.03, 0.14, 0.05), (0.01, 0.41, 0.02)]:
        n = samples_wanted(sigma, gain, target)
        assert sigma / abs(gain) / np.sqrt(n) <= target < sigma / abs(gain) / np.sqrt(n - 1)


def test_scatter_is_learnt_from_the_prior_and_the_residuals() -> None:
    memory = ScatterMemory(0.05)
    assert memory.sigma_px("a") == pytest.approx(0.05)
    memory.add("a", np.array([0.01, -0.01, 0.0]), 2)
    expected = np.sqrt((0.05**2 * PRIOR_RESIDUALS + 2e-4) / (PRIOR_RESIDUALS + 2))
    assert memory.sigma_px("a") == pytest.approx(expected)
    assert memory.sigma_px("b") == pytest.approx(0.05)  # per key


def test_detectors_of_one_kind_share_a_key() -> None:
    assert detector_kind(partial(find_marker, colour="red")) == detector_kind(
        partial(find_marker, colour="red")
    )
    assert detector_kind(partial(find_marker, colour="red")) != detector_kind(
        partial(find_marker, colour="green")
    )
    assert detector_kind(find_marker) is find_marker
    unhashable = partial(find_marker, colour=["red"])
    assert detector_kind(unhashable) is unhashable
