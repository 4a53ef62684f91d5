"""Other heads' pure math (docs/equations.md, "Beyond the paper: other heads"): exact synthetic
geometry, random points placed in W, the exact angles that fixate them, and the point recovered."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.estimators import model2
from headsim.geometry.heads import (
    Neck,
    RevoluteJoint,
    SerialChain,
    check_eye_axes,
    eye_axes_alignment,
    fixating_eye_angles,
    fixation_point_from_version_vergence,
    fixation_point_head,
    fixation_point_world,
    head_from_tilted_eyes,
    inward_from_version_vergence,
    paper_neck,
    pitch_roll_yaw_neck,
    tilt_to_plane,
    version_vergence,
)
from headsim.geometry.kinematics import (
    head_from_camera,
    head_to_camera,
    head_to_world,
    world_from_head,
)
from headsim.geometry.transforms import (
    homogeneous,
    invert_transform,
    rotation_x,
    rotation_y,
    rotation_z,
)

D = 0.068  # an iCub-like baseline, m
RTOL = 1e-12
AT_ZERO = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])  # H in W, eq. (1) at 0


def _points_in_front(rng: np.random.Generator, count: int, *, plane: bool) -> np.ndarray:
    """Points (count, 3) in an eye frame, 0.2-3 m ahead, |x/z| <= 0.6, y = 0 if ``plane``."""
    z = rng.uniform(0.2, 3.0, count)
    y = np.zeros(count) if plane else rng.uniform(-0.4, 0.4, count) * z
    return np.column_stack([rng.uniform(-0.6, 0.6, count) * z, y, z])


def _to(frame_from: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (N, 3) through poses (N, 4, 4) or one pose (4, 4)."""
    return np.einsum("...ij,...j->...i", frame_from[..., :3, :3], points) + frame_from[..., :3, 3]


def _inverse(poses: np.ndarray) -> np.ndarray:
    return np.stack([invert_transform(t) for t in poses.reshape(-1, 4, 4)]).reshape(poses.shape)


# --- item 1: one-step fixation with two eye motors -------------------------------------------


@pytest.mark.parametrize("los_offset", [(0.0, 0.0), (0.0015, -0.0008)])
def test_fixating_angles_put_the_point_on_both_optical_axes_and_it_comes_back(los_offset):
    rng = np.random.default_rng(11)
    points = _points_in_front(rng, 500, plane=False)
    alpha_e = (0.0578, -0.0254)
    pans = fixating_eye_angles(points, D, alpha_e, los_offset)
    # Independent check through the eye poses of kinematics: P sits on each optical axis.
    for camera, enc, e, side in zip(
        (1, 2), (pans.inward1_rad, pans.inward2_rad), alpha_e, los_offset, strict=True
    ):
        in_camera = head_to_camera(points, camera, enc + e, D, side=side)
        np.testing.assert_allclose(in_camera[:, 0], 0.0, atol=1e-15)
        assert (in_camera[:, 2] > 0.0).all()
    # Both angles read at once recover P's x and z; y is the plane's, 0.
    found = fixation_point_head(pans.inward1_rad, pans.inward2_rad, D, alpha_e, los_offset)
    in_plane = points * [1.0, 0.0, 1.0]
    np.testing.assert_allclose(found, in_plane, rtol=RTOL, atol=RTOL * np.abs(points).max())
    assert np.abs(found - in_plane).max() <= RTOL * np.linalg.norm(points, axis=1).min()


def test_one_step_x_and_z_are_model2s_eqs_4_5_with_the_same_offsets():
    rng = np.random.default_rng(12)
    alpha1, alpha2 = rng.uniform(0.02, 0.5, 200), rng.uniform(0.02, 0.5, 200)
    alpha_e, los = (0.03, -0.02), (0.001, 0.0005)
    uv = np.column_stack([rng.uniform(400, 600, 200), rng.uniform(50, 400, 200)])
    estimate = model2(
        alpha1,
        alpha2,
        uv,
        uv,
        D,
        uv10=(320.0, 240.0),
        uv20=(320.0, 240.0),
        alpha_e=alpha_e,
        los_offset_m=los,
    )
    assert estimate.valid.all()
    found = fixation_point_head(alpha1, alpha2, D, alpha_e, los)
    np.testing.assert_allclose(
        found[:, [0, 2]], estimate.positions[:, [0, 2]], rtol=1e-14, atol=1e-16
    )
    # And without offsets the paper's eqs. (4), (5) literally.
    plain = fixation_point_head(alpha1, alpha2, D)
    z = D / (np.tan(alpha1) + np.tan(alpha2))
    np.testing.assert_allclose(
        plain, np.column_stack([z * np.tan(alpha1) - D / 2, 0 * z, z]), rtol=1e-15
    )


def test_the_world_point_with_the_paper_neck_comes_back():
    rng = np.random.default_rng(13)
    d1, a2 = 0.12, 0.09
    n = 300
    theta1, theta2 = rng.uniform(-1.0, 1.0, n), rng.uniform(-0.6, 0.6, n)
    world_from_h = world_from_head(theta1, theta2, d1, a2)
    points_w = _to(world_from_h, _points_in_front(rng, n, plane=True))
    points_h = _to(_inverse(world_from_h), points_w)
    pans = fixating_eye_angles(points_h, D, (0.01, 0.02))
    found = fixation_point_world(pans.inward1_rad, pans.inward2_rad, D, world_from_h, (0.01, 0.02))
    assert np.abs(found - points_w).max() <= RTOL * np.linalg.norm(points_w, axis=1).min()


def test_degenerate_yaws_raise_naming_the_inputs():
    with pytest.raises(
        ValueError,
        match=r"alpha1_rad, alpha2_rad with alpha_e_rad give tan a1 \+ tan a2 <= 0.* for 1 of 2",
    ):
        fixation_point_head([0.1, -0.2], [0.05, 0.1], D)  # the second pair diverges
    with pytest.raises(ValueError, match=r"tan a1 \+ tan a2 <= 0.*a1 = 0\.0, a2 = 0\.0"):
        fixation_point_head(0.1, 0.0, D, alpha_e_rad=(-0.1, 0.0))  # parallel after the offsets
    with pytest.raises(ValueError, match=r"not finite with \|a_i\| < pi/2.*a1 = 1\.6"):
        fixation_point_head(1.6, 0.1, D)
    with pytest.raises(ValueError, match=r"cross behind the baseline, z <= 0"):
        fixation_point_head(0.3, 0.3, D, los_offset_m=(0.49 * D, -0.49 * D))
    with pytest.raises(ValueError, match=r"los_offset_m"):
        fixation_point_head(0.3, 0.3, D, los_offset_m=(D, 0.0))
    with pytest.raises(ValueError, match=r"baseline_m"):
        fixation_point_head(0.3, 0.3, 0.0)
    with pytest.raises(ValueError, match=r"world_from_eyes must have shape"):
        fixation_point_world(0.3, 0.3, D, np.eye(3))


# --- item 2: a common eye tilt ---------------------------------------------------------------


def test_tilt_looks_up_fixes_its_axis_and_is_a_one_joint_chain():
    rng = np.random.default_rng(21)
    axis_point = np.array([0.004, -0.012, -0.025])
    tau = 0.3
    h_from_e = head_from_tilted_eyes(tau, axis_point)
    assert h_from_e[1, 2] < 0.0 and h_from_e[2, 2] > 0.0  # E's z gains -y of H: up
    along_axis = axis_point + np.outer(rng.uniform(-1, 1, 5), [1.0, 0.0, 0.0])
    np.testing.assert_allclose(_to(h_from_e, along_axis), along_axis, atol=1e-17)
    taus = rng.uniform(-1.0, 1.0, 50)
    joint = RevoluteJoint(homogeneous(np.eye(3), axis_point), np.array([1.0, 0.0, 0.0]), "tilt")
    chain = SerialChain((joint,), homogeneous(np.eye(3), -axis_point))
    np.testing.assert_allclose(
        head_from_tilted_eyes(taus, axis_point), chain.world_from_head(taus[:, None]), atol=1e-17
    )
    np.testing.assert_array_equal(head_from_tilted_eyes(0.0)[:3, 3], 0.0)


def test_eq1_pitch_is_a_tilt_about_an_axis_a2_below_the_head():
    rng = np.random.default_rng(22)
    theta1, theta2 = rng.uniform(-2, 2, 100), rng.uniform(-1, 1, 100)
    d1, a2 = 0.3, 0.1
    composed = world_from_head(theta1, 0.0, d1, a2) @ head_from_tilted_eyes(theta2, [0.0, a2, 0.0])
    np.testing.assert_allclose(composed, world_from_head(theta1, theta2, d1, a2), atol=1e-15)


@pytest.mark.parametrize("axis_point", [(0.0, 0.0, 0.0), (0.0, -0.011, -0.02)])
def test_tilt_brings_the_point_to_the_eye_plane_and_it_comes_back(axis_point):
    rng = np.random.default_rng(23)
    n = 400
    d1, a2 = 0.12, 0.09
    theta1, theta2 = rng.uniform(-1.0, 1.0, n), rng.uniform(-0.5, 0.5, n)
    world_from_h = world_from_head(theta1, theta2, d1, a2)
    points_h = _points_in_front(rng, n, plane=False)
    points_w = _to(world_from_h, points_h)
    tau = tilt_to_plane(points_h, axis_point)
    world_from_e = world_from_h @ head_from_tilted_eyes(tau, axis_point)
    points_e = _to(_inverse(world_from_e), points_w)
    np.testing.assert_allclose(points_e[:, 1], 0.0, atol=1e-15)
    assert (points_e[:, 2] > 0.0).all()
    pans = fixating_eye_angles(points_e, D, (0.02, -0.01), (0.001, 0.001))
    found = fixation_point_world(
        pans.inward1_rad, pans.inward2_rad, D, world_from_e, (0.02, -0.01), (0.001, 0.001)
    )
    assert np.abs(found - points_w).max() <= RTOL * np.linalg.norm(points_w, axis=1).min()


# --- item 3: serial-chain necks --------------------------------------------------------------


def test_the_paper_neck_as_a_chain_is_eq1():
    rng = np.random.default_rng(31)
    for d1, a2 in ((0.12, 0.09), (0.0, 0.0), (0.4, 0.25)):
        angles = rng.uniform(-3.0, 3.0, (200, 2))
        chain = paper_neck(d1, a2).world_from_head(angles)
        np.testing.assert_allclose(
            chain, world_from_head(angles[:, 0], angles[:, 1], d1, a2), rtol=0, atol=1e-15
        )


def test_pitch_roll_yaw_chain_is_the_product_of_its_joints():
    rng = np.random.default_rng(32)
    r1, r2, r3 = (
        np.array([0.0, 0.01, 0.03]),
        np.array([0.002, 0.0, 0.033]),
        np.array([0.0, 0.054, 0.072]),
    )
    neck = pitch_roll_yaw_neck(r1, r2, r3)
    for pitch, roll, yaw in rng.uniform(-1.5, 1.5, (50, 3)):
        expected = (
            homogeneous(rotation_x(pitch), np.zeros(3))
            @ homogeneous(rotation_y(roll), r1)
            @ homogeneous(rotation_z(yaw), r2)
            @ homogeneous(AT_ZERO, r3)
        )
        np.testing.assert_allclose(neck.world_from_head([pitch, roll, yaw]), expected, atol=1e-15)
    assert neck.world_from_head(np.zeros((4, 7, 3))).shape == (4, 7, 4, 4)


def test_pitch_roll_yaw_signs():
    neck = pitch_roll_yaw_neck((0, 0, 0.1), (0, 0, 0.05), (0, 0.02, 0.07))
    up = neck.world_from_head([0.3, 0.0, 0.0])
    assert up[2, 2] > 0.0  # H's z (forward) gains +z in W: pitch up
    right = neck.world_from_head([0.0, 0.3, 0.0])
    assert -right[0, 1] > 0.0  # H's up (-y) tips towards +x: roll to the right
    np.testing.assert_allclose(right[:3, 2], [0.0, 1.0, 0.0], atol=1e-16)  # about the forward axis
    left = neck.world_from_head([0.0, 0.0, 0.3])
    assert left[0, 2] < 0.0  # forward turns to -x: yaw left, as eq. (1)'s theta1
    # Roll held at 0: pitch then yaw, not eq. (1)'s yaw then pitch (the order matters); with
    # the pitch axis at W's origin (eq. (1)'s d1 = 0) they agree where the yaw is 0.
    plain = pitch_roll_yaw_neck((0, 0, 0), (0, 0, 0), (0, 0, 0.09))
    assert not np.allclose(
        plain.world_from_head([0.4, 0.0, 0.7]), world_from_head(0.7, 0.4, 0.0, 0.09), atol=1e-3
    )
    np.testing.assert_allclose(
        plain.world_from_head([0.4, 0.0, 0.0]), world_from_head(0.0, 0.4, 0.0, 0.09), atol=1e-16
    )


def test_icub_like_head_recovers_random_world_points():
    """Neck pitch/roll/yaw with offsets, an offset eye tilt, independent eyes with offsets."""
    rng = np.random.default_rng(33)
    n = 500
    neck = pitch_roll_yaw_neck((0.0, 0.0, 0.034), (0.0, -0.0015, 0.033), (0.0, 0.054, 0.0825))
    angles = np.column_stack(
        [rng.uniform(-0.6, 0.4, n), rng.uniform(-0.5, 0.5, n), rng.uniform(-0.9, 0.9, n)]
    )
    world_from_h = neck.world_from_head(angles)
    points_w = _to(world_from_h, _points_in_front(rng, n, plane=False))
    axis_point, alpha_e, los = (0.0, -0.008, -0.022), (0.03, -0.04), (0.0005, -0.0012)
    tau = tilt_to_plane(_to(_inverse(world_from_h), points_w), axis_point)
    world_from_e = world_from_h @ head_from_tilted_eyes(tau, axis_point)
    pans = fixating_eye_angles(_to(_inverse(world_from_e), points_w), D, alpha_e, los)
    found = fixation_point_world(pans.inward1_rad, pans.inward2_rad, D, world_from_e, alpha_e, los)
    assert np.abs(found - points_w).max() <= RTOL * np.linalg.norm(points_w, axis=1).min()


def test_only_a_top_yaw_keeps_the_point_in_the_plane_of_the_optical_axes():
    """Model 1's midline servo: the iCub's top yaw turns about H's y, the paper's base yaw does not."""
    rng = np.random.default_rng(34)
    point_w = np.array([0.2, 0.9, 0.5])
    neck = pitch_roll_yaw_neck((0.0, 0.0, 0.034), (0.0, -0.0015, 0.033), (0.0, 0.054, 0.0825))
    pitch, roll = 0.3, -0.2
    yaws = rng.uniform(-0.8, 0.8, 20)
    angles = np.column_stack([np.full(20, pitch), np.full(20, roll), yaws])
    y_icub = _to(_inverse(neck.world_from_head(angles)), np.tile(point_w, (20, 1)))[:, 1]
    np.testing.assert_allclose(y_icub, y_icub[0], atol=1e-15)
    y_paper = _to(_inverse(world_from_head(yaws, 0.3, 0.12, 0.09)), np.tile(point_w, (20, 1)))[:, 1]
    assert np.ptp(y_paper) > 0.05


def test_a_yaw_pitch_neck_is_eq1_exactly():
    rng = np.random.default_rng(35)
    angles, points = rng.uniform(-1.0, 1.0, (40, 2)), rng.uniform(-1.0, 1.0, (40, 3))
    neck = Neck()
    assert np.array_equal(
        neck.world_from_head(angles[:, 0], angles[:, 1], 0.12, 0.09),
        world_from_head(angles[:, 0], angles[:, 1], 0.12, 0.09),
    )
    assert np.array_equal(
        neck.head_to_world(points, angles[:, 0], angles[:, 1], 0.12, 0.09),
        head_to_world(points, angles[:, 0], angles[:, 1], 0.12, 0.09),
    )


def test_a_pitch_yaw_neck_is_h6_with_the_roll_held_at_zero_and_its_own_chain():
    """(H10): the closed form, the (pitch, roll = 0, yaw) chain of (H6) and as_chain agree."""
    rng = np.random.default_rng(36)
    d1, a2, forward = 0.0095, 0.08205, 0.0509  # the iCub 2.0's, models/icub.xml
    neck = Neck("pitch_yaw", forward)
    icub = pitch_roll_yaw_neck((0.0, 0.0, d1), (0.0, 0.0, 0.0), (0.0, forward, a2))
    yaw, pitch = rng.uniform(-1.5, 1.5, 60), rng.uniform(-1.5, 1.5, 60)
    closed = neck.world_from_head(yaw, pitch, d1, a2)
    chain = icub.world_from_head(np.column_stack([pitch, np.zeros(60), yaw]))
    np.testing.assert_allclose(closed, chain, rtol=0, atol=1e-15)
    np.testing.assert_allclose(
        neck.as_chain(d1, a2).world_from_head(np.column_stack([pitch, yaw])), chain, atol=1e-15
    )
    points_h = rng.uniform(-1.0, 1.0, (60, 3))
    points_w = neck.head_to_world(points_h, yaw, pitch, d1, a2)
    np.testing.assert_allclose(
        neck.world_to_head(points_w, yaw, pitch, d1, a2), points_h, atol=1e-14
    )
    home = neck.world_from_head(0.0, 0.0, d1, a2)
    np.testing.assert_allclose(home[:3, 3], [0.0, forward, d1 + a2], atol=1e-16)
    assert neck.world_from_head(0.0, 0.3, d1, a2)[2, 2] > 0.0  # pitch up
    assert neck.world_from_head(0.3, 0.0, d1, a2)[0, 2] < 0.0  # yaw left
    with pytest.raises(ValueError, match="order must be one of yaw_pitch, pitch_yaw"):
        Neck("roll_pitch")
    with pytest.raises(ValueError, match="forward_m is for a pitch_yaw neck"):
        Neck("yaw_pitch", 0.01)


def test_chain_inputs_are_checked():
    with pytest.raises(ValueError, match="axis must be a unit vector"):
        RevoluteJoint(np.eye(4), np.array([1.0, 1.0, 0.0]))
    with pytest.raises(ValueError, match="rigid"):
        RevoluteJoint(2 * np.eye(4), np.array([1.0, 0.0, 0.0]))
    with pytest.raises(ValueError, match=r"angles_rad must have shape \(\.\.\., 2\)"):
        paper_neck(0.1, 0.1).world_from_head([0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="roll_from_pitch_m"):
        pitch_roll_yaw_neck((0, 0), (0, 0, 0), (0, 0, 0))


# --- item 4: version and vergence ------------------------------------------------------------


def test_version_vergence_round_trip_and_the_papers_counter_yaw():
    rng = np.random.default_rng(41)
    left, right = rng.uniform(-0.5, 0.8, 100), rng.uniform(-0.5, 0.8, 100)
    vv = version_vergence(left, right)
    back = inward_from_version_vergence(vv.version_rad, vv.vergence_rad)
    np.testing.assert_allclose(back.inward1_rad, left, rtol=0, atol=2e-16)
    np.testing.assert_allclose(back.inward2_rad, right, rtol=0, atol=2e-16)
    alpha = rng.uniform(0.0, 0.7, 10)
    paper = version_vergence(alpha, alpha)
    np.testing.assert_array_equal(paper.version_rad, 0.0)
    np.testing.assert_array_equal(paper.vergence_rad, 2 * alpha)


def test_positive_version_turns_both_optical_axes_to_plus_x():
    for version in (-0.4, 0.25):
        pans = inward_from_version_vergence(version, 0.0)
        axis1 = head_from_camera(1, pans.inward1_rad, D)[:3, 2]
        axis2 = head_from_camera(2, pans.inward2_rad, D)[:3, 2]
        np.testing.assert_allclose(axis1, [np.sin(version), 0.0, np.cos(version)], atol=1e-16)
        np.testing.assert_allclose(axis2, axis1, atol=1e-16)  # parallel at zero vergence
    pans = inward_from_version_vergence(
        0.1, 0.3
    )  # with vergence too: both azimuths grow with version
    more = inward_from_version_vergence(0.2, 0.3)
    assert more.inward1_rad > pans.inward1_rad and -more.inward2_rad > -pans.inward2_rad


def test_fixation_from_version_vergence_is_the_one_step_point_and_eq2_at_zero_version():
    rng = np.random.default_rng(42)
    version, vergence = rng.uniform(-0.4, 0.4, 300), rng.uniform(0.02, 1.0, 300)
    pans = inward_from_version_vergence(version, vergence)
    ok = (
        (pans.inward1_rad > -1.5)
        & (pans.inward2_rad > -1.5)
        & (np.tan(pans.inward1_rad) + np.tan(pans.inward2_rad) > 0)
    )
    closed = fixation_point_from_version_vergence(version[ok], vergence[ok], D)
    one_step = fixation_point_head(pans.inward1_rad[ok], pans.inward2_rad[ok], D)
    assert np.abs(closed - one_step).max() <= RTOL * np.linalg.norm(one_step, axis=1).min()
    at_midline = fixation_point_from_version_vergence(0.0, vergence, D)
    np.testing.assert_array_equal(at_midline[:, 0], 0.0)
    np.testing.assert_allclose(at_midline[:, 2], D / (2 * np.tan(vergence / 2)), rtol=1e-14)
    # One vergence, one circle through C1 and C2: the angle C1 P C2 is the vergence.
    to1, to2 = [-D / 2, 0, 0] - closed, [D / 2, 0, 0] - closed
    cos_at_p = np.sum(to1 * to2, axis=1) / np.linalg.norm(to1, axis=1) / np.linalg.norm(to2, axis=1)
    np.testing.assert_allclose(np.arccos(cos_at_p), vergence[ok], rtol=1e-9)
    with pytest.raises(ValueError, match=r"0 < vergence < pi.*vergence -0\.1"):
        fixation_point_from_version_vergence(0.0, [0.2, -0.1], D)


# --- item 5: eye axes -------------------------------------------------------------------------


def test_the_paper_heads_axes_are_exactly_aligned():
    # Ca1 turns inward about +y of H, Ca2 about -y: antiparallel, which as lines is parallel.
    found = check_eye_axes([0, 1, 0], [0, -1, 0], [1, 0, 0], tolerance_rad=0.0)
    assert (
        found.between_axes_rad,
        found.axis1_off_perpendicular_rad,
        found.axis2_off_perpendicular_rad,
    ) == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("angle", [1e-9, 1e-4, 0.3, 1.2])
def test_axis_angles_are_exact_small_and_large(angle):
    c, s = np.cos(angle), np.sin(angle)
    turned = eye_axes_alignment([0, 1, 0], [0, c, s], [1, 0, 0])  # axis 2 turned about the baseline
    assert turned.between_axes_rad == pytest.approx(angle, rel=RTOL)
    assert (turned.axis1_off_perpendicular_rad, turned.axis2_off_perpendicular_rad) == (0.0, 0.0)
    leaning = eye_axes_alignment(
        [s, c, 0], [0, -2, 0], [3, 0, 0]
    )  # axis 1 leans along the baseline
    assert leaning.between_axes_rad == pytest.approx(angle, rel=RTOL)
    assert leaning.axis1_off_perpendicular_rad == pytest.approx(angle, rel=RTOL)
    assert leaning.axis2_off_perpendicular_rad == 0.0
    assert leaning.worst_rad == pytest.approx(angle, rel=RTOL)
    assert leaning.within(angle * 1.01) and not leaning.within(angle * 0.99)


def test_axis_angles_in_any_frame():
    rng = np.random.default_rng(51)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    b, u, w = q[:, 0], q[:, 1], q[:, 2]  # baseline, and two directions perpendicular to it
    beta1, beta2, phi = 0.05, 0.02, 0.03
    axis1 = np.cos(beta1) * u + np.sin(beta1) * b
    axis2 = -(np.cos(beta2) * (np.cos(phi) * u + np.sin(phi) * w) + np.sin(beta2) * b)
    found = eye_axes_alignment(axis1, axis2, -b)
    assert found.axis1_off_perpendicular_rad == pytest.approx(beta1, rel=1e-13)
    assert found.axis2_off_perpendicular_rad == pytest.approx(beta2, rel=1e-13)
    between = np.arccos(abs(axis1 @ axis2))
    assert found.between_axes_rad == pytest.approx(between, rel=1e-10)


def test_check_eye_axes_names_what_is_wrong():
    with pytest.raises(ValueError, match=r"not parallel: 0\.1 rad apart.*tolerance 0\.01 rad"):
        check_eye_axes([0, 1, 0], [0, np.cos(0.1), np.sin(0.1)], [1, 0, 0], tolerance_rad=0.01)
    with pytest.raises(
        ValueError, match=r"eye axis 1 not perpendicular to the baseline: 0\.05 rad"
    ):
        check_eye_axes(
            [np.sin(0.05), np.cos(0.05), 0], [np.sin(0.05), np.cos(0.05), 0], [1, 0, 0], 0.01
        )
    with pytest.raises(ValueError, match="axis2 must be a non-zero"):
        eye_axes_alignment([0, 1, 0], [0, 0, 0], [1, 0, 0])
