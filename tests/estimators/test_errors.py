"""Error propagation: the paper's formulas (15)-(21) and the general covariance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.estimators import (
    Uncertainty,
    model2,
    model2_jacobian,
    rel_dx_model2,
    rel_dy_model2,
    rel_dy_model2_simplified,
    rel_dz_correspondence,
    rel_dz_model1,
    rel_dz_model1_small_angle,
    rel_dz_model2,
    rel_dz_model2_small_angle,
)
from headsim.geometry.synthetic import StereoHead, observe

from .helpers import random_points

D = 0.15
CENTRE = (319.5, 239.5)
H = 1e-3  # central-difference step, as a fraction of each sampled input error


def _z1(d, a):
    return d / (2.0 * np.tan(a))  # eq. (2)


def _xyz2(d, a1, a2, u1d=40.0, v1d=50.0, u2d=45.0, v2d=60.0):
    """Eqs. (4)-(11) with zero offsets, as the paper differentiates them."""
    z = d / (np.tan(a1) + np.tan(a2))
    s = np.sin(a1 - a2)
    y = 0.5 * (v1d / u1d * s / np.cos(a1) + v2d / u2d * s / np.cos(a2)) * z
    return z * np.tan(a1) - d / 2.0, y, z


def test_model1_formulas_are_the_derivative_of_eq2():
    rng = np.random.default_rng(41)
    a = rng.uniform(0.02, 0.6, 200)
    rel_dd, da = rng.normal(0, 1e-3, 200), rng.normal(0, 1e-4, 200)
    fd = (_z1(D * (1 + rel_dd * H), a + da * H) - _z1(D * (1 - rel_dd * H), a - da * H)) / (
        2 * H * _z1(D, a)
    )
    np.testing.assert_allclose(rel_dz_model1(a, rel_dd, da), fd, rtol=1e-6, atol=1e-12)
    # (16) drops O(alpha^2) of (15)'s angle term: 2/sin(2a) - 1/a = 2a/3 + O(a^3).
    gap = rel_dz_model1_small_angle(a, rel_dd, da) - rel_dz_model1(a, rel_dd, da)
    assert np.all(np.abs(gap) <= np.abs(da) * a)
    small = a < 0.05
    np.testing.assert_allclose(gap[small], (da * 2.0 * a / 3.0)[small], rtol=5e-3)


def test_model2_depth_and_x_formulas_are_the_derivative_of_eqs_4_5():
    rng = np.random.default_rng(42)
    a1, a2 = rng.uniform(0.01, 0.6, 200), rng.uniform(0.01, 0.6, 200)
    rel_dd, da1, da2 = (rng.normal(0, s, 200) for s in (1e-3, 1e-4, 1e-4))
    _, _, z0 = _xyz2(D, a1, a2)
    xp, _, zp = _xyz2(D * (1 + rel_dd * H), a1 + da1 * H, a2 + da2 * H)
    xm, _, zm = _xyz2(D * (1 - rel_dd * H), a1 - da1 * H, a2 - da2 * H)
    rel_dz = rel_dz_model2(a1, a2, rel_dd, da1, da2)
    np.testing.assert_allclose(rel_dz, (zp - zm) / (2 * H * z0), rtol=1e-6, atol=1e-12)
    dx = rel_dx_model2(a1, rel_dz, D * rel_dd, z0, da1)
    np.testing.assert_allclose(dx, (xp - xm) / (2 * H * z0), rtol=1e-6, atol=1e-12)
    # (18) is (17) to first order in the angles: the gap is O(a da).
    gap = rel_dz_model2_small_angle(a1, a2, rel_dd, da1, da2) - rel_dz
    assert np.all(np.abs(gap) <= (np.abs(da1) + np.abs(da2)) * (a1 + a2))
    small = (a1 < 0.02) & (a2 < 0.02)
    assert np.all(
        np.abs(gap[small]) <= 0.05 * (np.abs(da1) + np.abs(da2))[small] / (a1 + a2)[small]
    )


def test_correspondence_error_in_depth_is_eye_2_turned_by_du_over_f():
    # (M5): a target straight ahead at z; camera 2's match du px off turns eye 2 by
    # du / f.  Exact: the depth where eye 1's ray meets eye 2's turned ray.
    z, f, du = 1.0, 840.0, 0.1
    a = math.atan(D / (2.0 * z))
    exact = D / (math.tan(a) + math.tan(a + du / f)) / z - 1.0
    rel = float(rel_dz_correspondence(a, a, du, f))
    assert rel == pytest.approx(exact, rel=2e-3)
    assert abs(rel) == pytest.approx(z * du / (D * f), rel=1e-2)  # ~ z du / (D f)


def test_model2_y_formula_is_the_derivative_of_eqs_9_to_11():
    rng = np.random.default_rng(43)
    a1, a2 = rng.uniform(0.05, 0.6, 200), rng.uniform(0.01, 0.5, 200)
    pix = rng.uniform(20.0, 200.0, (4, 200)) * rng.choice([-1.0, 1.0], (4, 200))
    rel_dd, da1, da2 = (rng.normal(0, s, 200) for s in (1e-3, 1e-4, 1e-4))
    dpix = rng.normal(0, 0.3, (4, 200))
    _, _, z0 = _xyz2(D, a1, a2, *pix)
    _, yp, _ = _xyz2(D * (1 + rel_dd * H), a1 + da1 * H, a2 + da2 * H, *(pix + dpix * H))
    _, ym, _ = _xyz2(D * (1 - rel_dd * H), a1 - da1 * H, a2 - da2 * H, *(pix - dpix * H))
    rel_dz = rel_dz_model2(a1, a2, rel_dd, da1, da2)
    u1d, v1d, u2d, v2d = pix
    du1, dv1, du2, dv2 = dpix
    dy = rel_dy_model2(a1, a2, u1d, v1d, u2d, v2d, rel_dz, da1, da2, du1, dv1, du2, dv2)
    np.testing.assert_allclose(dy, (yp - ym) / (2 * H * z0), rtol=1e-6, atol=1e-12)
    # (21) is (20) without the angle and du terms.
    simplified = rel_dy_model2_simplified(a1, a2, u1d, v1d, u2d, v2d, rel_dz, dv1, dv2)
    np.testing.assert_allclose(
        simplified,
        rel_dy_model2(a1, a2, u1d, v1d, u2d, v2d, rel_dz, dv1d=dv1, dv2d=dv2),
        rtol=1e-12,
    )


def test_paper_worked_example_dy_over_z_is_at_most_1_1_percent():
    # Sec. IV: a1 = pi/6, a2 = pi/12, u1d = 40, v1d = 50, u2d = 45, v2d = 60,
    # dz/z = 2 %.  The extracted text reads "dv1d = 50, dv2d = 50", which gives
    # 33 %; the decimal point was lost: dv = 0.5 px gives the paper's bound.
    a1, a2 = math.pi / 6, math.pi / 12
    dy = rel_dy_model2_simplified(a1, a2, 40.0, 50.0, 45.0, 60.0, 0.02, 0.5, 0.5)
    assert 0.0 < dy <= 0.011
    assert rel_dy_model2_simplified(a1, a2, 40.0, 50.0, 45.0, 60.0, 0.02, 50.0, 50.0) > 0.3
    # The same figure from the general Jacobian: with zero offsets and images at
    # the paper's eye angles, dD/D = 2 % and dv = 0.5 px contribute linearly.
    jac = model2_jacobian(
        np.array([a1]),
        np.array([a2]),
        np.array([a2]),
        np.array([a1]),
        np.array([[40.0, 50.0]]),
        np.array([[45.0, 60.0]]),
        D,
    )
    z = D / (math.tan(a1) + math.tan(a2))
    dy_general = (jac[0, 1, 0] * 0.02 * D + jac[0, 1, 6] * 0.5 + jac[0, 1, 8] * 0.5) / z
    assert dy_general == pytest.approx(dy, rel=1e-12)


def _observe(head, points, remedy):
    kw = {"gamma1": 0.0, "gamma2": 0.0} if remedy else {}
    return observe(head, points, **kw), kw


@pytest.mark.parametrize("remedy", [False, True], ids=["paper-images", "images-at-0"])
def test_jacobian_matches_central_differences(remedy):
    rng = np.random.default_rng(44)
    head = StereoHead(D, alpha_e1=0.03, alpha_e2=-0.02)
    e = head.effective_initial_directions()
    points = random_points(rng, 40, (0.3, 2.5), azimuth=0.35)
    points[:, 0] += np.sign(points[:, 0]) * 0.05
    obs, _ = _observe(head, points, remedy)
    g1 = obs.gamma1 if remedy else obs.alpha2
    g2 = obs.gamma2 if remedy else obs.alpha1
    jac = model2_jacobian(obs.alpha1, obs.alpha2, g1, g2, obs.uv1 - CENTRE, obs.uv2 - CENTRE, D, e)
    base = [D, obs.alpha1, obs.alpha2, g1, g2, *obs.uv1.T, *obs.uv2.T]
    steps = [1e-6, 1e-7, 1e-7, 1e-7, 1e-7, 1e-4, 1e-4, 1e-4, 1e-4]

    def estimate(args):
        d, a1, a2, c1, c2, u1, v1, u2, v2 = args
        est = model2(
            a1,
            a2,
            np.stack([u1, v1], -1),
            np.stack([u2, v2], -1),
            d,
            uv10=CENTRE,
            uv20=CENTRE,
            alpha_e=e,
            gamma1=c1,
            gamma2=c2,
        )
        return est.positions

    for k, step in enumerate(steps):
        hi, lo = list(base), list(base)
        hi[k], lo[k] = base[k] + step, base[k] - step
        fd = (estimate(hi) - estimate(lo)) / (2 * step)
        np.testing.assert_allclose(jac[:, :, k], fd, rtol=1e-5, atol=1e-7 * np.abs(fd).max())


def _working_points(head, remedy):
    """Eight points in the working range (0.25-3 m, one per depth band) whose images are in
    view and at least 10 px off the target column (the working range of eq. (9)-(10))."""
    rng = np.random.default_rng(450)
    candidates = random_points(rng, 4000, (0.25, 3.0), azimuth=0.4, elevation=0.3)
    obs, _ = _observe(head, candidates, remedy)
    ud = np.minimum(np.abs(obs.uv1[:, 0] - CENTRE[0]), np.abs(obs.uv2[:, 0] - CENTRE[0]))
    usable = obs.in_view & (ud >= 10.0)
    bands = np.digitize(np.linalg.norm(candidates, axis=1), np.linspace(0.25, 3.0, 9))
    picks = [np.flatnonzero(usable & (bands == b))[0] for b in range(1, 9)]
    return candidates[picks]


@pytest.mark.parametrize("remedy", [False, True], ids=["paper-images", "images-at-0"])
def test_covariance_matches_monte_carlo_over_the_working_range(remedy):
    rng = np.random.default_rng(45)
    head = StereoHead(D, alpha_e1=0.0578, alpha_e2=-0.0254)
    e = head.effective_initial_directions()
    points = _working_points(head, remedy)
    obs, kw = _observe(head, points, remedy)
    unc = Uncertainty(baseline=0.5e-3, encoder=head.encoder_resolution, pixel=0.3)
    ref = model2(
        obs.alpha1,
        obs.alpha2,
        obs.uv1,
        obs.uv2,
        D,
        uv10=CENTRE,
        uv20=CENTRE,
        alpha_e=e,
        uncertainty=unc,
        **kw,
    )
    n = 100_000
    worst = 0.0
    for i in range(len(points)):
        a1 = obs.alpha1[i] + rng.normal(0.0, unc.encoder, n)
        a2 = obs.alpha2[i] + rng.normal(0.0, unc.encoder, n)
        gammas = {k: v + rng.normal(0.0, unc.encoder, n) for k, v in kw.items()}
        uv1 = obs.uv1[i] + rng.normal(0.0, unc.pixel, (n, 2))
        uv2 = obs.uv2[i] + rng.normal(0.0, unc.pixel, (n, 2))
        d = D + rng.normal(0.0, unc.baseline, n)
        # Every coordinate is proportional to D: estimate with D = 1, scale by the sample.
        est = model2(a1, a2, uv1, uv2, 1.0, uv10=CENTRE, uv20=CENTRE, alpha_e=e, **gammas)
        assert est.valid.all()
        sampled = np.std(est.positions * d[:, None], axis=0)
        analytic = np.sqrt(np.diag(ref.covariance[i]))
        worst = max(worst, np.abs(sampled / analytic - 1.0).max())
        # Correlations too: the y-z correlation carries the shared dz/z term.
        corr_mc = np.corrcoef((est.positions * d[:, None]).T)
        corr = ref.covariance[i] / np.outer(analytic, analytic)
        np.testing.assert_allclose(corr_mc, corr, atol=0.02)
    print(f"Monte Carlo vs analytic std ({n} samples, {len(points)} points): worst {worst:.2%}")
    assert worst < 0.10
