"""Relative positioning: eq. (12) on pixels against the geometric ground truth, and Q1."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.estimators import (
    Q1Side,
    areas_from_geometry,
    areas_from_pixels,
    compare_areas,
    q1_columns,
    q1_side,
)
from headsim.geometry.camera_model import PinholeCamera, paper_cam1, paper_cam2
from headsim.geometry.synthetic import StereoHead, fixation_angles, image_points

D = 0.15
MAGNITUDE_PAIRS = {(1, 2), (2, 1), (3, 4), (4, 3), (7, 8), (8, 7)}


def _layouts(
    head: StereoHead,
    rng: np.random.Generator,
    n_layouts: int,
    k: int = 60,
    ref_x: tuple[float, float] = (-0.3, 0.3),
    ref_z: tuple[float, float] = (0.4, 2.0),
):
    """Random reference + k objects per layout; yields what eq. (12) and its truth need."""
    for _ in range(n_layouts):
        while True:
            ref = np.array([[rng.uniform(*ref_x), rng.uniform(-0.05, 0.05), rng.uniform(*ref_z)]])
            fix = fixation_angles(head, ref)
            if fix.valid[0]:
                break
        a1, a2 = float(fix.alpha1[0]), float(fix.alpha2[0])
        z = rng.uniform(0.25, 3.0, k)
        objects = np.stack(
            [z * np.tan(rng.uniform(-0.35, 0.35, k)), rng.uniform(-0.1, 0.1, k) * z, z], -1
        )
        cols = [
            image_points(head, objects, cam, a)[:, 0]
            for cam, a in ((1, a1), (1, a2), (2, a1), (2, a2))
        ]
        seen = np.all(
            [
                head.camera(c).contains(image_points(head, objects, c, a))
                for c, a in ((1, a1), (1, a2), (2, a1), (2, a2))
            ],
            axis=0,
        )
        yield ref, objects[seen], a1, a2, [c[seen] for c in cols]


def _run(head, rng, n_layouts, kx=None):
    u10, u20 = head.target_columns
    totals = np.zeros(4, int)
    swaps_outside: set[tuple[int, int]] = set()
    seen_true: set[int] = set()
    for _ref, objects, a1, a2, cols in _layouts(head, rng, n_layouts):
        pixel = areas_from_pixels(*cols, u10, u20, alpha1=a1, alpha2=a2, kx=kx)
        truth = areas_from_geometry(objects, a1, a2, D, head.effective_initial_directions())
        cmp = compare_areas(pixel, truth, *cols, u10, u20, threshold_px=2.0)
        totals += [cmp.n_objects, cmp.n_disagree_outside, cmp.n_inside, cmp.n_disagree_inside]
        outside = ~cmp.agree & (cmp.margin > 2.0)
        swaps_outside |= set(zip(pixel[outside].tolist(), truth[outside].tolist(), strict=True))
        seen_true |= set(truth.tolist())
    return totals, swaps_outside, seen_true


def test_pixels_agree_with_geometry_beyond_2_px_on_random_layouts(record_property):
    # kx != ky and unequal initial directions; both eyes with the same kx, as the paper's
    # magnitude tests assume.
    cam = PinholeCamera(640, 480, 700.0, 650.0, 319.5, 239.5)
    head = StereoHead(D, cam, cam, alpha_e1=0.0578, alpha_e2=-0.0254)
    (n, out, inside, dis_in), _, seen = _run(head, np.random.default_rng(51), 150)
    record_property(
        "areas_ideal",
        f"{n} objects, {out} wrong beyond 2 px, {dis_in} wrong of {inside} within 2 px",
    )
    print(
        f"eq. (12), equal cameras: {n} objects, {out} disagree beyond 2 px, "
        f"{dis_in} of {inside} within 2 px disagree"
    )
    assert n > 5000
    assert out == 0
    assert seen == set(range(1, 13))  # every area occurs and no object is unclassified


def test_paper_cameras_only_swap_across_the_magnitude_boundary(record_property):
    # Unequal focal lengths shift the magnitude tests (docs/equations.md); the sign
    # tests survive any intrinsics and the radial distortion.
    head = StereoHead(D, paper_cam1(), paper_cam2(), alpha_e1=0.0578, alpha_e2=-0.0254)
    for kx in (None, (head.cam1.kx, head.cam2.kx)):
        (n, out, inside, dis_in), swaps, _ = _run(head, np.random.default_rng(52), 100, kx=kx)
        label = "pixels" if kx is None else "pixels / kx"
        record_property(
            f"areas_paper_{label}",
            f"{n} objects, {out} wrong beyond 2 px, {dis_in} wrong of {inside} within 2 px",
        )
        print(
            f"eq. (12), paper cameras, {label}: {n} objects, {out} disagree beyond 2 px, "
            f"{dis_in} of {inside} within 2 px disagree"
        )
        assert swaps <= MAGNITUDE_PAIRS


def test_geometric_magnitude_test_is_the_z_axis_for_symmetric_eyes():
    rng = np.random.default_rng(53)
    head = StereoHead(D, alpha_e1=0.02, alpha_e2=0.02)
    for ref, objects, a1, a2, _cols in _layouts(head, rng, 50):
        truth = areas_from_geometry(objects, a1, a2, D, (0.02, 0.02))
        x = objects[:, 0]
        assert np.all(x[np.isin(truth, (1, 3, 7))] < 0) and np.all(x[np.isin(truth, (2, 4, 8))] > 0)
        assert ref.shape == (1, 3)


def test_mirror_image_gets_the_mirrored_area():
    rng = np.random.default_rng(54)
    head = StereoHead(D)
    mirror = np.array([0, 2, 1, 4, 3, 6, 5, 8, 7, 10, 9, 12, 11])
    flip = np.array([-1.0, 1.0, 1.0])
    for ref, objects, a1, a2, cols in _layouts(head, rng, 30):
        direct = areas_from_pixels(*cols, 319.5, 319.5, alpha1=a1, alpha2=a2)
        fix = fixation_angles(head, ref * flip)
        b1, b2 = float(fix.alpha1[0]), float(fix.alpha2[0])
        assert (b1, b2) == pytest.approx((a2, a1), abs=1e-14)
        m = objects * flip
        mcols = [image_points(head, m, c, a)[:, 0] for c, a in ((1, b1), (1, b2), (2, b1), (2, b2))]
        mirrored = areas_from_pixels(*mcols, 319.5, 319.5, alpha1=b1, alpha2=b2)
        np.testing.assert_array_equal(mirrored, mirror[direct])
        np.testing.assert_array_equal(areas_from_geometry(m, b1, b2, D), mirrored)


def test_inconsistent_or_nan_columns_are_unclassified():
    # u12 < u10 but u11 > u10 is impossible with alpha1 > alpha2.
    areas = areas_from_pixels(
        [330.0, np.nan],
        [300.0, 300.0],
        [300.0, 300.0],
        [330.0, 330.0],
        319.5,
        319.5,
        alpha1=0.08,
        alpha2=0.0349,
    )
    np.testing.assert_array_equal(areas, [0, 0])
    with pytest.raises(ValueError, match="one shape"):
        areas_from_pixels([1.0, 2.0], [1.0], [1.0], [1.0], 0.0, 0.0, alpha1=0.1, alpha2=0.0)


def test_q1_columns_and_sides_follow_the_geometry():
    rng = np.random.default_rng(55)
    head = StereoHead(D, alpha_e1=0.01, alpha_e2=-0.01)
    e = head.effective_initial_directions()
    checked = 0
    for ref, objects, a1, a2, _ in _layouts(head, rng, 40, ref_x=(0.01, 0.06), ref_z=(1.0, 2.5)):
        if not 0.01 < a1 - a2 < 0.1:
            continue  # (14) divides by alpha1 - alpha2 and is linear in the angles
        checked += 1
        z = float(ref[0, 2])
        u211 = image_points(head, ref, 2, a1)[0, 0]
        u121 = image_points(head, ref, 1, a2)[0, 0]
        u21q, u12q = q1_columns(z, a1, a2, u211, u121, 319.5, 319.5, D, e)
        q = np.array([[0.0, 0.0, z]])
        true21, true12 = image_points(head, q, 2, a1)[0, 0], image_points(head, q, 1, a2)[0, 0]
        # (14) trades tan for proportionality: good to a fraction of a pixel at the
        # paper's angles (alpha1 - alpha2 = 0.045 in Sec. VI-C).
        assert abs(u21q - true21) < 0.2 and abs(u12q - true12) < 0.2
        side = q1_side(
            image_points(head, objects, 1, a2)[:, 0],
            image_points(head, objects, 2, a1)[:, 0],
            true12,
            true21,
        )
        # Geometry: angles of the objects against the rays C1-Q1 and C2-Q1.
        phi1 = np.arctan2(objects[:, 0] + D / 2, objects[:, 2]) - np.arctan2(D / 2, z)
        phi2 = np.arctan2(objects[:, 0] - D / 2, objects[:, 2]) - np.arctan2(-D / 2, z)
        expected = np.select(
            [(phi1 > 0) & (phi2 < 0), (phi1 < 0) & (phi2 > 0), (phi1 < 0) & (phi2 < 0)],
            [Q1Side.NEAR, Q1Side.FAR, Q1Side.LEFT],
            Q1Side.RIGHT,
        )
        np.testing.assert_array_equal(side, expected)
        assert np.all(objects[side == Q1Side.NEAR, 2] < z)
    assert checked >= 30


def test_q1_needs_two_different_fixations():
    with pytest.raises(ValueError, match="alpha1 != alpha2"):
        q1_columns(1.0, 0.05, 0.05, 330.0, 330.0, 319.5, 319.5, D)
