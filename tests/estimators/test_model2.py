"""Model 2 (eqs. 4-11) against the exact forward model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.estimators import Flag, model2, model2_jacobian
from headsim.geometry.camera_model import PinholeCamera, ideal, paper_cam1, paper_cam2
from headsim.geometry.kinematics import head_to_world
from headsim.geometry.synthetic import StereoHead, observe

from .helpers import random_points, remedy_gammas

D = 0.15
CENTRE = (319.5, 239.5)


def _estimate(head: StereoHead, obs, **kw):
    c1, c2 = head.cam1, head.cam2
    return model2(
        obs.alpha1,
        obs.alpha2,
        obs.uv1,
        obs.uv2,
        head.baseline,
        uv10=(head.target_columns[0], c1.cy),
        uv20=(head.target_columns[1], c2.cy),
        alpha_e=head.effective_initial_directions(),
        kx_over_ky=(c1.kx / c1.ky, c2.kx / c2.ky),
        **kw,
    )


@pytest.mark.parametrize(
    "offsets", [(0.0, 0.0), (0.0578, -0.0254)], ids=["no-offsets", "paper-offsets"]
)
def test_exact_recovery_of_10000_points_in_head_and_world(offsets):
    rng = np.random.default_rng(20260)
    points = random_points(rng, 10_000)
    head = StereoHead(D, alpha_e1=offsets[0], alpha_e2=offsets[1])
    first = observe(head, points)
    g1, g2 = remedy_gammas(first.alpha1, first.alpha2, head.cam1.kx, min_ud=2.0)
    obs = observe(head, points, gamma1=g1, gamma2=g2)
    assert obs.valid.all()

    est = _estimate(head, obs, gamma1=g1, gamma2=g2)

    assert est.valid.all() and (est.flags == 0).all()
    rel = np.linalg.norm(est.positions - points, axis=1) / np.linalg.norm(points, axis=1)
    assert rel.max() < 1e-9
    theta1, theta2 = rng.uniform(-1.0, 1.0, 10_000), rng.uniform(-0.6, 0.6, 10_000)
    world = est.to_world(theta1, theta2, d1=0.35, a2=0.08)
    truth_w = head_to_world(points, theta1, theta2, 0.35, 0.08)
    rel_w = np.linalg.norm(world.positions - truth_w, axis=1) / np.linalg.norm(truth_w, axis=1)
    assert world.frame == "W" and rel_w.max() < 1e-9


def test_recovery_is_exact_with_unequal_focal_lengths_and_offset_principal_point():
    # Eq. (7) needs only kx/ky and the principal row; the target column only shifts
    # the effective initial directions.
    rng = np.random.default_rng(11)
    cam1 = PinholeCamera(640, 480, 834.83, 815.42, 303.8, 306.3)
    cam2 = PinholeCamera(640, 480, 850.46, 833.29, 345.1, 197.3)
    head = StereoHead(D, cam1, cam2, alpha_e1=0.03, alpha_e2=-0.01, u10=cam1.cx, u20=cam2.cx)
    points = random_points(rng, 2000, (0.3, 2.5))
    obs = observe(head, points)
    g1, g2 = remedy_gammas(obs.alpha1, obs.alpha2, cam1.kx, min_ud=2.0)
    obs = observe(head, points, gamma1=g1, gamma2=g2)
    est = _estimate(head, obs, gamma1=g1, gamma2=g2)
    assert est.valid.all()
    np.testing.assert_allclose(est.positions, points, rtol=0, atol=1e-12)


def test_image_centre_target_moves_only_the_initial_directions():
    # u10 != cx: x_h and z_h stay exact with the effective initial directions.
    rng = np.random.default_rng(12)
    cam1 = PinholeCamera(640, 480, 834.83, 834.83, 303.8, 239.5)
    head = StereoHead(D, cam1, ideal(), alpha_e1=0.02)
    points = random_points(rng, 2000, (0.3, 2.5))
    obs = observe(head, points)
    est = _estimate(head, obs)
    ok = est.valid
    np.testing.assert_allclose(est.positions[ok][:, [0, 2]], points[ok][:, [0, 2]], atol=1e-12)


def test_distorted_cameras_recover_points_in_the_plane_of_the_axes():
    # With distortion the effective initial direction depends on the image row;
    # measured at the principal row it is exact for points with y_h = 0.
    rng = np.random.default_rng(13)
    cam1, cam2 = paper_cam1(), paper_cam2()
    head = StereoHead(D, cam1, cam2, alpha_e1=0.0578, alpha_e2=-0.0254)
    points = random_points(rng, 2000, (0.3, 2.5), azimuth=0.3, elevation=0.0)
    first = observe(head, points)
    g1, g2 = remedy_gammas(first.alpha1, first.alpha2, cam1.kx, min_ud=2.0)
    obs = observe(head, points, gamma1=g1, gamma2=g2)
    e1, e2 = (head.effective_initial_directions(v) for v in (cam1.cy, cam2.cy))
    est = model2(
        obs.alpha1,
        obs.alpha2,
        obs.uv1,
        obs.uv2,
        D,
        uv10=(319.5, cam1.cy),
        uv20=(319.5, cam2.cy),
        alpha_e=(e1[0], e2[1]),
        gamma1=g1,
        gamma2=g2,
    )
    assert obs.valid.all() and est.valid.all()
    np.testing.assert_allclose(est.positions, points, atol=1e-12)


def test_near_midline_default_images_are_flagged_and_remedy_recovers():
    head = StereoHead(D)
    points = np.array([[0.0, 0.1, 1.0], [0.0, -0.2, 2.0], [1e-5, 0.05, 0.5]])
    obs = observe(head, points)
    est = _estimate(head, obs)
    assert not est.valid.any()
    assert all(Flag.NO_Y in est.reasons(i) for i in range(3))
    assert np.isnan(est.positions).all()
    # The paper's remedy: Ca1's image at eye angle 0, Ca2's at 0.
    obs0 = observe(head, points, gamma1=0.0, gamma2=0.0)
    est0 = _estimate(head, obs0, gamma1=0.0, gamma2=0.0)
    assert est0.valid.all()
    np.testing.assert_allclose(est0.positions, points, atol=1e-13)


def test_one_small_u_offset_uses_the_other_camera():
    head = StereoHead(D)
    points = random_points(np.random.default_rng(14), 50, (0.4, 2.0))
    points[:, 0] += np.where(points[:, 0] < 0, -0.05, 0.05)  # off the midline: |u2d| > 1 px
    obs = observe(head, points)
    # Ca1's image taken at the step-1 angle itself: P sits on u10, eq. (9) is 0/0.
    uv1 = observe(head, points, gamma1=obs.alpha1).uv1
    est = model2(
        obs.alpha1, obs.alpha2, uv1, obs.uv2, D, uv10=CENTRE, uv20=CENTRE, gamma1=obs.alpha1
    )
    assert est.valid.all()
    assert all(est.reasons(i) == Flag.SMALL_U1D for i in range(50))
    assert np.isnan(est.y_cam[:, 0]).all() and np.isfinite(est.y_cam[:, 1]).all()
    np.testing.assert_allclose(est.positions, points, atol=1e-12)


def test_degenerate_points_are_flagged_without_touching_the_others():
    head = StereoHead(D)
    points = random_points(np.random.default_rng(15), 6, (0.5, 1.5), azimuth=0.3)
    obs = observe(head, points)
    a1, a2 = obs.alpha1.copy(), obs.alpha2.copy()
    uv1 = obs.uv1.copy()
    a1[1], a2[1] = -0.05, 0.02  # lines of sight diverge: a1 + a2 <= 0
    a1[2] = np.nan
    uv1[3, 1] = np.inf
    a1[4] = math.pi / 2 + 0.1  # camera turned past 90 degrees
    est = model2(a1, a2, uv1, obs.uv2, D, uv10=CENTRE, uv20=CENTRE)
    assert est.valid.tolist() == [True, False, False, False, False, True]
    assert est.reasons(1) == Flag.NOT_CONVERGING
    assert Flag.NONFINITE in est.reasons(2) and Flag.NONFINITE in est.reasons(3)
    assert Flag.BEHIND_CAMERA in est.reasons(4)
    assert np.isnan(est.positions[1:5]).all()
    np.testing.assert_allclose(est.positions[[0, 5]], points[[0, 5]], atol=1e-12)


def test_zero_sum_of_eye_angles_is_not_converging():
    est = model2(
        [0.01, 0.0],
        [-0.01, 0.0],
        [[400.0, 250.0]] * 2,
        [[400.0, 250.0]] * 2,
        D,
        uv10=CENTRE,
        uv20=CENTRE,
    )
    assert not est.valid.any()
    assert all(Flag.NOT_CONVERGING in est.reasons(i) for i in range(2))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"alpha1": [0.1, 0.2]}, r"alpha2 must have shape \(2,\)"),
        ({"uv1": [[1.0, 2.0, 3.0]]}, r"uv1 must have shape \(1, 2\)"),
        ({"alpha1": [30.0]}, "alpha1 must be in radians"),
        ({"baseline": 150.0}, "baseline must be in metres"),
        ({"gamma1": [0.1, 0.2]}, r"gamma1 must be a scalar or have shape \(1,\)"),
        ({"kx_over_ky": (1.0, -1.0)}, "kx_over_ky must be two positive ratios"),
    ],
)
def test_wrong_shapes_and_units_raise(kwargs, message):
    args = {
        "alpha1": [0.1],
        "alpha2": [0.05],
        "uv1": [[400.0, 250.0]],
        "uv2": [[380.0, 250.0]],
        "baseline": D,
    }
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        model2(uv10=CENTRE, uv20=CENTRE, **args)


def test_quantised_eye_angles_err_as_the_jacobian_predicts():
    # Rounded fixation angles leave P off its target column; the estimate then
    # errs by the Jacobian times the rounding (the images are exact for the
    # angles they were taken at), up to second order.
    rng = np.random.default_rng(16)
    head = StereoHead(D, alpha_e1=0.01, alpha_e2=0.02)
    points = random_points(rng, 3000, (0.3, 3.0), azimuth=0.4)
    exact = observe(head, points)
    obs = observe(head, points, quantised=True)
    step = head.encoder_resolution
    d1, d2 = obs.alpha1 - exact.alpha1, obs.alpha2 - exact.alpha2
    assert np.all(np.abs(d1) <= step / 2 + 1e-15) and np.all(np.abs(d2) <= step / 2 + 1e-15)
    np.testing.assert_allclose(obs.alpha1 / step, np.round(obs.alpha1 / step), atol=1e-9)
    e = head.effective_initial_directions()
    est = model2(
        obs.alpha1,
        obs.alpha2,
        obs.uv1,
        obs.uv2,
        D,
        uv10=CENTRE,
        uv20=CENTRE,
        alpha_e=e,
        min_abs_ud=20.0,
    )
    ok = est.valid
    assert ok.mean() > 0.9
    jac = model2_jacobian(
        exact.alpha1,
        exact.alpha2,
        exact.alpha2,
        exact.alpha1,
        exact.uv1 - CENTRE,
        exact.uv2 - CENTRE,
        D,
        e,
    )
    predicted = jac[..., 1] * d1[:, None] + jac[..., 2] * d2[:, None]
    residual = (est.positions - points - predicted)[ok]
    # Second order only: the residual is a small fraction of the predicted error.
    rms_ratio = np.sqrt(np.mean(residual**2, axis=0) / np.mean(predicted[ok] ** 2, axis=0))
    assert np.all(rms_ratio < 0.02)
