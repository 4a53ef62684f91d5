"""The vertical reference fit (estimators/vertical.py): exact recovery and clear refusals."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.estimators.vertical import calibrate_vertical_reference


def _samples(r: float, v0: float, rng: np.random.Generator, n: int = 12):
    u_d = rng.uniform(20.0, 200.0, n) * rng.choice([-1.0, 1.0], n)
    v = rng.uniform(40.0, 440.0, n)
    x_c = rng.uniform(0.1, 0.4, n)
    y_c = r * (v - v0) * x_c / u_d  # eq. (7) solved for y: exact synthetic samples
    return u_d, v, x_c, y_c


def test_exact_samples_give_back_the_ratio_and_the_row(rng) -> None:
    fit = calibrate_vertical_reference(*_samples(1.0238, 241.7, rng))
    assert fit.kx_over_ky == pytest.approx(1.0238, abs=1e-12)
    assert fit.v0 == pytest.approx(241.7, abs=1e-9)
    assert fit.v0_std < 1e-9 and fit.kx_over_ky_std < 1e-12
    assert np.abs(fit.residuals_m).max() < 1e-12


def test_noisy_samples_give_standard_errors_that_cover_the_truth(rng) -> None:
    u_d, v, x_c, y_c = _samples(0.98, 250.0, rng, n=200)
    fit = calibrate_vertical_reference(u_d, v + rng.normal(0.0, 0.5, v.size), x_c, y_c)
    assert 0.0 < fit.v0_std < 1.0 and 0.0 < fit.kx_over_ky_std < 0.01
    assert abs(fit.v0 - 250.0) < 4 * fit.v0_std
    assert abs(fit.kx_over_ky - 0.98) < 4 * fit.kx_over_ky_std


def test_bad_samples_are_refused_with_the_reason(rng) -> None:
    u_d, v, x_c, y_c = _samples(1.0, 240.0, rng)
    with pytest.raises(ValueError, match="one length"):
        calibrate_vertical_reference(u_d, v[:-1], x_c, y_c)
    with pytest.raises(ValueError, match="at least 3 samples, got 2"):
        calibrate_vertical_reference(u_d[:2], v[:2], x_c[:2], y_c[:2])
    with pytest.raises(ValueError, match="finite"):
        calibrate_vertical_reference(u_d, np.where(v > 300, np.nan, v), x_c, y_c)
    with pytest.raises(ValueError, match="not positive"):
        calibrate_vertical_reference(u_d, v, x_c, -y_c)
