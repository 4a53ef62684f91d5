"""Image noise: the rounded-Gaussian law, its spread, independence and seed (real arrays)."""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np
import pytest

from headsim.sim.imperfections.noise import GaussianNoise

GREY = np.full((480, 640, 3), 128, dtype=np.uint8)


def _offsets(noise: GaussianNoise, key: tuple[int, ...], frame: int) -> np.ndarray:
    return noise.apply(GREY, key, frame).astype(int) - 128


def _rounded_gaussian(std: float, k: int) -> float:
    normal = NormalDist(0.0, std)
    return normal.cdf(k + 0.5) - normal.cdf(k - 0.5)


@pytest.mark.parametrize("std", [0.4, 1.0, 2.0, 7.5, 25.0])
def test_the_law_is_the_rounded_gaussian_to_two_to_the_minus_16(std: float) -> None:
    law = GaussianNoise.of(std).probabilities()
    assert math.isclose(sum(law.values()), 1.0, abs_tol=1e-12)
    k_max = max(abs(k) for k in law)
    for k in range(-k_max - 3, k_max + 4):
        assert abs(law.get(k, 0.0) - _rounded_gaussian(std, k)) <= 2.0**-16, k
    # Only a tail rarer than 1e-4 on each side is folded into the extreme values.
    assert 1.0 - NormalDist(0.0, std).cdf(k_max + 0.5) < 1e-4


@pytest.mark.parametrize("std", [2.0, 30.0])
def test_samples_follow_the_law_with_the_stated_spread(std: float) -> None:
    noise = GaussianNoise.of(std)
    samples = np.concatenate([_offsets(noise, (3, 0), f).ravel() for f in range(4)])
    n = samples.size
    # Rounding to whole grey levels adds 1/12 to the variance, as clip(rint(x + std z)) does.
    expected_std = math.sqrt(sum(k * k * _rounded_gaussian(std, k) for k in range(-300, 301)))
    assert abs(expected_std**2 - std**2 - 1 / 12) < 0.01 * std**2
    unclipped = samples[(samples > -128) & (samples < 127)]
    assert unclipped.size > 0.9999 * n
    assert abs(samples.std() - expected_std) < 0.003 * expected_std
    assert abs(samples.mean()) < 5 * std / math.sqrt(n)
    # Each count against the sampler's own law (the rounded Gaussian to 2**-16 each, which
    # is 56 of these 3.7 M samples: a rare outcome's count is judged against its table's).
    law = noise.probabilities()
    values, counts = np.unique(samples, return_counts=True)
    for k, count in zip(values, counts, strict=True):
        if not -128 < k < 127:
            continue  # saturated at black or white
        p = law.get(int(k), 0.0)
        assert abs(count - n * p) <= 6 * math.sqrt(n * p * (1 - p)) + 3, k


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.corrcoef(a.ravel().astype(float), b.ravel().astype(float))[0, 1])


def test_noise_is_independent_between_pixels_channels_frames_and_cameras() -> None:
    noise = GaussianNoise.of(3.0)
    first, second = _offsets(noise, (0, 0), 0), _offsets(noise, (0, 0), 1)
    other_camera = _offsets(noise, (0, 1), 0)
    bound = 5.0 / math.sqrt(first[..., 0].size)
    pairs = {
        "horizontal neighbours": (first[:, 1:], first[:, :-1]),
        "vertical neighbours": (first[1:], first[:-1]),
        "colour channels": (first[..., 0], first[..., 1]),
        "next frame": (first, second),
        "other camera": (first, other_camera),
    }
    for name, (a, b) in pairs.items():
        assert abs(_correlation(a, b)) < bound, name


def test_noise_follows_the_seed_and_saturates_like_clipping() -> None:
    noise = GaussianNoise.of(4.0)
    np.testing.assert_array_equal(noise.apply(GREY, (7, 0), 5), noise.apply(GREY, (7, 0), 5))
    assert np.any(noise.apply(GREY, (7, 0), 5) != noise.apply(GREY, (8, 0), 5))
    assert np.any(noise.apply(GREY, (7, 0), 5) != noise.apply(GREY, (7, 0), 6))
    # Any image gets the same offsets, clipped to [0, 255] as clip(rint(image + std z)).
    image = np.random.default_rng(1).integers(0, 256, GREY.shape, dtype=np.uint8)
    expected = np.clip(image.astype(int) + _offsets(noise, (7, 0), 5), 0, 255)
    np.testing.assert_array_equal(noise.apply(image, (7, 0), 5), expected)
    assert GaussianNoise.of(0.0).apply(image, (7, 0), 5) is image


@pytest.mark.parametrize("std", [3.0, 30.0])
@pytest.mark.parametrize("full_size", [(640, 480), (203, 97)])
def test_a_windows_noise_is_the_full_frames_crop(std: float, full_size: tuple[int, int]) -> None:
    # Drawn for the window's rows only, from any corner, in colour and in grey: exactly
    # the noise of the full frame there (a width whose rows do not fill whole blocks too).
    noise = GaussianNoise.of(std)
    width, height = full_size
    rng = np.random.default_rng(2)
    for shape in ((height, width, 3), (height, width)):
        image = rng.integers(0, 256, shape, dtype=np.uint8)
        full = noise.apply(image, (5, 1), 9)
        for x0, y0, w, h in ((0, 0, width, height), (17, 3, 40, 31), (width - 1, height - 1, 1, 1)):
            part = np.ascontiguousarray(image[y0 : y0 + h, x0 : x0 + w])
            window = noise.apply(part, (5, 1), 9, crop=(x0, y0, width, height))
            np.testing.assert_array_equal(window, full[y0 : y0 + h, x0 : x0 + w])
