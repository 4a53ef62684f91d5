"""Model 1 (eqs. 2-3) against the exact neck-and-eyes forward model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.estimators import Flag, Uncertainty, model1
from headsim.geometry.kinematics import head_to_world, world_to_head
from headsim.geometry.synthetic import StereoHead, image_points
from headsim.geometry.synthetic_neck import neck_fixation

from .helpers import random_points

D, D1, A2 = 0.15, 0.35, 0.08


@pytest.mark.parametrize("offset", [0.0, 0.03])
def test_exact_recovery_of_10000_points_in_head_and_world(offset):
    rng = np.random.default_rng(31)
    # True points at 0.2-3 m from a head at a random neck pose, expressed in W.
    theta1, theta2 = rng.uniform(-1.0, 1.0, 10_000), rng.uniform(-0.5, 0.5, 10_000)
    points_w = head_to_world(random_points(rng, 10_000), theta1, theta2, D1, A2)
    head = StereoHead(D, alpha_e1=offset, alpha_e2=offset)
    fix = neck_fixation(head, points_w, D1, A2)
    assert fix.valid.all()

    est = model1(fix.alpha, D, alpha_e=offset)

    assert est.valid.all()
    truth_h = world_to_head(points_w, fix.theta1, fix.theta2, D1, A2)
    rel_h = np.linalg.norm(est.positions - truth_h, axis=1) / np.linalg.norm(truth_h, axis=1)
    assert rel_h.max() < 1e-9
    world = est.to_world(fix.theta1, fix.theta2, D1, A2)
    rel_w = np.linalg.norm(world.positions - points_w, axis=1) / np.linalg.norm(points_w, axis=1)
    assert rel_w.max() < 1e-9


def test_neck_fixation_centres_the_point_in_both_cameras():
    rng = np.random.default_rng(32)
    points_w = head_to_world(random_points(rng, 500), 0.3, -0.2, D1, A2)
    head = StereoHead(D, alpha_e1=0.0578, alpha_e2=-0.0254)
    fix = neck_fixation(head, points_w, D1, A2)
    assert fix.valid.all()
    p_h = world_to_head(points_w, fix.theta1, fix.theta2, D1, A2)
    np.testing.assert_allclose(p_h, fix.points_h, atol=1e-12)
    np.testing.assert_allclose(p_h[:, 1], 0.0, atol=1e-12)  # in the plane of the optical axes
    for camera, u0 in zip((1, 2), head.target_columns, strict=True):
        uv = image_points(head, p_h, camera, fix.alpha)
        np.testing.assert_allclose(uv[:, 0], u0, atol=1e-10)
    # Unequal offsets: the crossing of the lines of sight leaves the Z_h axis.
    assert np.abs(p_h[:, 0]).min() > 0.0


def test_symmetric_fixation_matches_the_closed_form():
    points_w = np.array([[0.3, 1.2, 0.9], [-0.5, 0.4, 0.2], [0.0, 2.5, 0.4]])
    head = StereoHead(D, alpha_e1=0.01, alpha_e2=0.01)
    fix = neck_fixation(head, points_w, D1, A2)
    p_h = world_to_head(points_w, fix.theta1, fix.theta2, D1, A2)
    np.testing.assert_allclose(p_h[:, :2], 0.0, atol=1e-12)
    np.testing.assert_allclose(fix.alpha, np.arctan(D / (2.0 * p_h[:, 2])) - 0.01, atol=1e-14)


def test_unreachable_points_are_flagged():
    head = StereoHead(D)
    # On the yaw axis, inside the pitch radius, and NaN.
    points_w = np.array([[0.0, 0.0, 1.5], [0.0, 0.01, D1], [np.nan, 1.0, 0.5], [0.2, 1.0, 0.5]])
    fix = neck_fixation(head, points_w, D1, A2)
    assert fix.valid.tolist() == [False, False, False, True]
    assert np.isnan(fix.alpha[:3]).all() and np.isnan(fix.theta1[:3]).all()


def test_degenerate_angles_are_flagged():
    est = model1([0.05, 0.0, -0.01, np.nan, math.pi / 2], D)
    assert est.valid.tolist() == [True, False, False, False, False]
    assert est.reasons(1) == Flag.NOT_CONVERGING and est.reasons(2) == Flag.NOT_CONVERGING
    assert est.reasons(3) == Flag.NONFINITE
    assert est.reasons(4) == Flag.BEHIND_CAMERA
    assert np.isnan(est.positions[1:]).all()
    np.testing.assert_allclose(est.positions[0], [0.0, 0.0, D / (2.0 * math.tan(0.05))])


@pytest.mark.parametrize(
    ("alpha", "baseline", "message"),
    [
        ([[0.1]], D, r"alpha must be a scalar or have shape \(N,\)"),
        ([5.0], D, "alpha must be in radians"),
        ([0.1], 0.0, "baseline must be in metres"),
    ],
)
def test_wrong_input_raises(alpha, baseline, message):
    with pytest.raises(ValueError, match=message):
        model1(alpha, baseline)


def test_covariance_matches_monte_carlo():
    rng = np.random.default_rng(33)
    unc = Uncertainty(baseline=0.5e-3, encoder=2.45e-4)
    alphas = np.array([0.0251, 0.05, 0.1, 0.3])  # z from 3 m down to 0.24 m
    ref = model1(alphas, D, uncertainty=unc)
    n = 200_000
    for i, a in enumerate(alphas):
        d = D + rng.normal(0.0, unc.baseline, n)
        # z_h is proportional to D: estimate with D = 1 and scale by the sampled D.
        z = model1(a + rng.normal(0.0, unc.encoder, n), 1.0).positions[:, 2] * d
        assert np.std(z) / math.sqrt(ref.covariance[i, 2, 2]) == pytest.approx(1.0, abs=0.10)
    assert np.all(ref.covariance[:, :2, :] == 0.0)


def test_unequal_offsets_are_exact_with_the_pair():
    rng = np.random.default_rng(32)
    theta1, theta2 = rng.uniform(-1.0, 1.0, 2_000), rng.uniform(-0.5, 0.5, 2_000)
    points_w = head_to_world(random_points(rng, 2_000), theta1, theta2, D1, A2)
    head = StereoHead(D, alpha_e1=0.0578, alpha_e2=-0.0254)
    fix = neck_fixation(head, points_w, D1, A2)
    ok = fix.valid
    assert ok.mean() > 0.9
    exact = model1(fix.alpha[ok], D, alpha_e=(0.0578, -0.0254))
    truth_h = world_to_head(points_w[ok], fix.theta1[ok], fix.theta2[ok], D1, A2)
    rel = np.linalg.norm(exact.positions - truth_h, axis=1) / np.linalg.norm(truth_h, axis=1)
    assert rel.max() < 1e-9
    assert np.abs(truth_h[:, 0]).max() > 1e-3  # the fixated point is off the Z_h axis
    # The mean offset in eq. (2) is only first-order right.
    mean = model1(fix.alpha[ok], D, alpha_e=(0.0578 - 0.0254) / 2)
    assert np.linalg.norm(mean.positions - truth_h, axis=1).max() > 1e-4
