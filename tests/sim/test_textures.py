"""Generated textures: their spectra and periods, exactly, from the FFT."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.sim.textures import (
    TEXTURE_KINDS,
    TextureSpec,
    pink_noise,
    spectrum_slope,
    texture_grey,
    tint_of,
    to_rgb,
)


@pytest.mark.parametrize("seed", [0, 1, 7])
def test_pink_noise_has_a_one_over_f_amplitude_spectrum(seed: int) -> None:
    grey = texture_grey(TextureSpec("pink", seed=seed))
    assert spectrum_slope(grey) == pytest.approx(-1.0, abs=1e-9)
    # Quantised to 8 bits for MuJoCo, the slope holds to a few thousandths.
    eight_bit = to_rgb(grey)[..., 0].astype(float)
    assert spectrum_slope(eight_bit) == pytest.approx(-1.0, abs=3e-3)
    assert grey.min() >= 0.0 and grey.max() <= 1.0


def test_the_slope_measure_tells_other_exponents_and_white_noise() -> None:
    rng = np.random.default_rng(3)
    assert spectrum_slope(pink_noise(128, rng, exponent=2.0)) == pytest.approx(-2.0, abs=1e-9)
    white = rng.standard_normal((256, 256))
    assert abs(spectrum_slope(white)) < 0.05


def _peak_bin(image: np.ndarray) -> tuple[int, int]:
    spectrum = np.abs(np.fft.fft2(image - image.mean()))
    row, col = np.unravel_index(int(spectrum.argmax()), spectrum.shape)
    n = image.shape[0]
    # The signed frequency bins (the peak and its mirror are equal: take col >= 0).
    r, c = (row + n // 2) % n - n // 2, (col + n // 2) % n - n // 2
    return (-r, -c) if c < 0 or (c == 0 and r < 0) else (r, c)


@pytest.mark.parametrize(
    ("period_px", "orientation_rad", "expected_bin"),
    [
        (16.0, 0.0, (0, 16)),  # 256 / 16 cycles along the columns
        (32.0, math.pi / 2, (8, 0)),  # along the rows
        (6.4, math.atan2(3.0, 4.0), (24, 32)),  # 40 cycles along (0.8, 0.6)
    ],
)
def test_a_grating_has_its_period_and_orientation_in_the_fft(
    period_px: float, orientation_rad: float, expected_bin: tuple[int, int]
) -> None:
    grey = texture_grey(
        TextureSpec("grating", seed=2, period_px=period_px, orientation_rad=orientation_rad)
    )
    assert _peak_bin(grey) == expected_bin
    spectrum = np.abs(np.fft.fft2(grey - grey.mean())) ** 2
    assert spectrum.max() * 2 / spectrum.sum() > 0.999  # one frequency and its mirror


def test_repetitive_stripes_repeat_at_their_period_and_checks_in_two_directions() -> None:
    stripes = texture_grey(TextureSpec("repetitive", period_px=16.0))
    assert _peak_bin(stripes) == (0, 16)
    np.testing.assert_array_equal(stripes, np.roll(stripes, 16, axis=1))
    checks = texture_grey(TextureSpec("repetitive", period_px=16.0, checks=True))
    np.testing.assert_array_equal(checks, np.roll(checks, 16, axis=0))
    np.testing.assert_array_equal(checks, -np.roll(checks, 8, axis=0) + 1.0)


def test_low_texture_has_little_fine_detail() -> None:
    def fine(grey: np.ndarray) -> float:
        return float(np.abs(np.diff(grey, axis=1)).mean())

    low = texture_grey(TextureSpec("low", seed=4))
    pink = texture_grey(TextureSpec("pink", seed=4))
    assert fine(low) < fine(pink) / 3
    assert float(np.ptp(low)) < 0.5


@pytest.mark.parametrize("kind", TEXTURE_KINDS)
def test_the_same_seed_gives_the_same_texture_and_another_seed_another(kind: str) -> None:
    a = texture_grey(TextureSpec(kind, seed=11))
    np.testing.assert_array_equal(a, texture_grey(TextureSpec(kind, seed=11)))
    if kind != "repetitive":  # stripes have no random part
        assert not np.array_equal(a, texture_grey(TextureSpec(kind, seed=12)))


def test_tints_are_pale_so_no_texture_is_a_markers_colour() -> None:
    for seed in range(50):
        assert all(0.7 <= c <= 1.0 for c in tint_of(seed))


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"kind": "plaid"}, "unknown texture 'plaid'"),
        ({"kind": "pink", "size_px": 4}, "size_px"),
        ({"kind": "grating", "period_px": 1.0}, "period_px"),
        ({"kind": "pink", "contrast": 0.0}, "contrast"),
    ],
)
def test_a_bad_texture_is_refused_by_name(fields: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        TextureSpec(**fields)
