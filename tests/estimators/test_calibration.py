"""Calibration of the initial directions, eqs. (22)-(26)."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.estimators import calibrate_initial_directions, calibration_coefficients
from headsim.geometry.camera_model import PinholeCamera, ideal
from headsim.geometry.synthetic import StereoHead, fixation_angles

D = 0.15
PAPER_OFFSETS = (0.0578, -0.0254)


def _targets(rng: np.random.Generator, n: int) -> np.ndarray:
    """n calibration targets (n, 3) in H spread over depth and across the view."""
    z = rng.uniform(0.3, 1.5, n)
    x = rng.uniform(-0.4, 0.4, n) * z
    return np.stack([x, np.zeros(n), z], axis=-1)


def test_noiseless_data_recover_the_paper_offsets():
    head = StereoHead(D, alpha_e1=PAPER_OFFSETS[0], alpha_e2=PAPER_OFFSETS[1])
    targets = _targets(np.random.default_rng(61), 12)
    fix = fixation_angles(head, targets)
    # Eq. (23): every coefficient row vanishes at the true tangents.
    coeffs = calibration_coefficients(fix.alpha1, fix.alpha2, targets[:, 2], D)
    x, y = np.tan(PAPER_OFFSETS)
    np.testing.assert_allclose(coeffs @ np.array([x * y, x, y, 1.0]), 0.0, atol=1e-15)

    cal = calibrate_initial_directions(fix.alpha1, fix.alpha2, targets[:, 2], D)

    assert cal.converged
    np.testing.assert_allclose(cal.alpha_e, PAPER_OFFSETS, rtol=0, atol=1e-9)
    np.testing.assert_allclose(cal.depth_residuals, 0.0, atol=1e-12)
    assert np.all(cal.std_errors < 1e-9)


def test_calibration_finds_the_effective_directions_of_an_off_centre_principal_point():
    # The servo fixates the image centre, not the principal point: what Model 2
    # needs (and what the calibration sees) is the effective initial direction.
    cam = PinholeCamera(640, 480, 834.83, 815.42, 303.8, 306.3)
    head = StereoHead(D, cam, ideal(), alpha_e1=0.02, alpha_e2=-0.01)
    targets = _targets(np.random.default_rng(62), 20)
    fix = fixation_angles(head, targets)
    cal = calibrate_initial_directions(fix.alpha1, fix.alpha2, targets[:, 2], D)
    np.testing.assert_allclose(cal.alpha_e, head.effective_initial_directions(), atol=1e-9)
    assert abs(cal.alpha_e[0] - 0.02) > 0.01  # the principal-point shift is really there


def _spread(head, rng, trials, n, sigma_enc, sigma_z, weighted):
    targets = _targets(rng, n)
    fix = fixation_angles(head, targets)
    estimates, errors = [], []
    for _ in range(trials):
        a1 = fix.alpha1 + rng.normal(0.0, sigma_enc, n)
        a2 = fix.alpha2 + rng.normal(0.0, sigma_enc, n)
        z = targets[:, 2] + rng.normal(0.0, sigma_z, n)
        kw = {"sigma_encoder": sigma_enc, "sigma_depth": sigma_z} if weighted else {}
        cal = calibrate_initial_directions(a1, a2, z, D, **kw)
        assert cal.converged and cal.weighted == weighted
        estimates.append(cal.alpha_e)
        errors.append(cal.std_errors)
    return np.std(estimates, axis=0), np.sqrt(np.mean(np.square(errors), axis=0))


@pytest.mark.parametrize(
    ("sigma_enc", "sigma_z", "weighted"),
    [(1e-4, 0.0, False), (1e-4, 2e-3, True)],
    ids=["encoder-noise-unweighted", "encoder-and-depth-noise-weighted"],
)
def test_standard_errors_agree_with_the_spread_over_trials(sigma_enc, sigma_z, weighted):
    head = StereoHead(D, alpha_e1=PAPER_OFFSETS[0], alpha_e2=PAPER_OFFSETS[1])
    spread, reported = _spread(
        head, np.random.default_rng(63), 250, 30, sigma_enc, sigma_z, weighted
    )
    print(f"calibration std errors / spread: {reported / spread}")
    np.testing.assert_allclose(reported / spread, 1.0, atol=0.20)


def test_two_samples_solve_exactly_without_standard_errors():
    head = StereoHead(D, alpha_e1=PAPER_OFFSETS[0], alpha_e2=PAPER_OFFSETS[1])
    targets = np.array([[-0.3, 0.0, 0.5], [0.35, 0.0, 0.9]])
    fix = fixation_angles(head, targets)
    cal = calibrate_initial_directions(fix.alpha1, fix.alpha2, targets[:, 2], D)
    np.testing.assert_allclose(cal.alpha_e, PAPER_OFFSETS, atol=1e-9)
    assert np.isnan(cal.std_errors).all()


@pytest.mark.parametrize(
    ("alpha1", "alpha2", "z", "message"),
    [
        ([0.1], [0.1], [1.0], "at least two samples"),
        ([0.1, np.nan], [0.1, 0.1], [1.0, 1.0], "must be finite"),
        ([0.1, 0.2], [0.1, 0.2], [1.0, -1.0], "z_h must be > 0"),
        ([0.1, 0.2], [0.1], [1.0, 1.0], "one shape"),
        ([10.0, 20.0], [0.1, 0.1], [1.0, 1.0], "alpha1 must be in radians"),
        ([0.07, 0.07, 0.07], [0.08, 0.08, 0.08], [1.0, 1.0, 1.0], "do not separate"),
    ],
)
def test_bad_samples_raise(alpha1, alpha2, z, message):
    with pytest.raises(ValueError, match=message):
        calibrate_initial_directions(alpha1, alpha2, z, D)
