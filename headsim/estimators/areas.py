"""Relative positioning of several objects (Sec. III): the 12 areas of eq. (12) and Q1.

Lines: L11, L12 are Ca1's lines of sight in steps 1 and 2 (eye angles alpha1,
alpha2), L21, L22 Ca2's.  For object k, ``d_ij`` is its offset from line L_ij
as seen in camera i's image j: on pixels ``u_ijk - u_i0`` (eq. 12); on true
geometry ``tan`` of its horizontal angle to the line (ground truth).  Areas
are numbered 1..12 as S1..S12; 0 means unclassified (a tie, NaN, or a sign
pattern no real object can have).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from headsim.estimators.result import as_vector, check_baseline

__all__ = [
    "AreaComparison",
    "Q1Side",
    "areas_from_geometry",
    "areas_from_pixels",
    "compare_areas",
    "q1_columns",
    "q1_side",
    "tally_areas",
]

# Area labels of the mirror image x_h -> -x_h (camera 1 <-> 2, step 1 <-> 2).
_MIRROR = np.array([0, 2, 1, 4, 3, 6, 5, 8, 7, 10, 9, 12, 11])


def _table(d11: np.ndarray, d12: np.ndarray, d21: np.ndarray, d22: np.ndarray) -> np.ndarray:
    """Eq. (12) on offsets from the four lines, assuming alpha1 > alpha2; (K,) int areas."""
    rows = [
        (d12 < 0) & (d22 > 0) & (np.abs(d12) > np.abs(d22)),
        (d12 < 0) & (d22 > 0) & (np.abs(d12) < np.abs(d22)),
        (d11 < 0) & (d12 > 0) & (d21 > 0) & (d22 < 0) & (np.abs(d11) > np.abs(d21)),
        (d11 < 0) & (d12 > 0) & (d21 > 0) & (d22 < 0) & (np.abs(d11) < np.abs(d21)),
        (d11 < 0) & (d12 > 0) & (d21 < 0),
        (d11 > 0) & (d21 > 0) & (d22 < 0),
        (d11 > 0) & (d21 < 0) & (np.abs(d11) < np.abs(d21)),
        (d11 > 0) & (d21 < 0) & (np.abs(d11) > np.abs(d21)),
        (d12 < 0) & (d21 > 0) & (d22 < 0),
        (d11 < 0) & (d12 > 0) & (d22 > 0),
        (d12 < 0) & (d21 < 0),
        (d11 > 0) & (d22 > 0),
    ]
    hits = np.stack(rows)
    # A consistent object matches exactly one row; anything else is unclassified.
    return np.where(hits.sum(axis=0) == 1, np.argmax(hits, axis=0) + 1, 0)


def _classify(
    d11: np.ndarray, d12: np.ndarray, d21: np.ndarray, d22: np.ndarray, alpha1_gt_alpha2: bool
) -> np.ndarray:
    """Eq. (12) for either order of the reference's eye angles."""
    direct = _table(d11, d12, d21, d22)
    # For alpha1 < alpha2 apply the table to the mirror image: offsets flip sign,
    # cameras and steps swap (Ca1 step j <-> Ca2 step 3-j).
    mirrored = _MIRROR[_table(-d22, -d21, -d12, -d11)]
    return np.where(alpha1_gt_alpha2, direct, mirrored)


def areas_from_pixels(
    u11: ArrayLike,
    u12: ArrayLike,
    u21: ArrayLike,
    u22: ArrayLike,
    u10: float,
    u20: float,
    *,
    alpha1: float,
    alpha2: float,
    kx: tuple[float, float] | None = None,
) -> np.ndarray:
    """Eq. (12): areas (K,) of K objects from their columns u_ijk, px, in camera i's image j.

    alpha1, alpha2: the reference's eye angles, rad; eq. (12) is written for
    alpha1 > alpha2 (reference right of Z_h) and is applied to the mirror image
    otherwise.  kx: (kx1, kx2), px, to compare angles instead of raw pixel
    offsets in the magnitude tests; None (the paper) compares pixels.
    """
    cols = [
        as_vector(u, name) for u, name in ((u11, "u11"), (u12, "u12"), (u21, "u21"), (u22, "u22"))
    ]
    if len({c.shape for c in cols}) != 1:
        raise ValueError(
            f"u11, u12, u21, u22 must have one shape (K,), got {[c.shape for c in cols]}"
        )
    s1, s2 = (1.0, 1.0) if kx is None else (1.0 / kx[0], 1.0 / kx[1])
    d11, d12 = (cols[0] - u10) * s1, (cols[1] - u10) * s1
    d21, d22 = (cols[2] - u20) * s2, (cols[3] - u20) * s2
    return _classify(d11, d12, d21, d22, alpha1 > alpha2)


def areas_from_geometry(
    points_h: ArrayLike,
    alpha1: float,
    alpha2: float,
    baseline: float,
    alpha_e: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """Ground truth of eq. (12): the same table on tangents of the true angles to each line, (K,).

    points_h: (K, 3) objects in H, m.  alpha1, alpha2: the reference's eye angles,
    rad.  alpha_e: effective initial directions, rad (the lines are the rays the
    servo put on the target columns).  Heights are ignored: only the horizontal
    angles count, as in Fig. 6.
    """
    p = np.asarray(points_h, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points_h must have shape (K, 3), got {p.shape}")
    half = check_baseline(baseline) / 2.0
    phi1 = np.arctan2(p[:, 0] + half, p[:, 2])
    phi2 = np.arctan2(p[:, 0] - half, p[:, 2])
    e1, e2 = alpha_e
    d11, d12 = np.tan(phi1 - alpha1 - e1), np.tan(phi1 - alpha2 - e1)
    d21, d22 = np.tan(phi2 + alpha1 + e2), np.tan(phi2 + alpha2 + e2)
    return _classify(d11, d12, d21, d22, alpha1 > alpha2)


@dataclass(frozen=True)
class AreaComparison:
    """Eq. (12) on pixels against the ground truth, with a margin in px.

    margin: (K,) px, the smallest of the pixel quantities that decide the
    area (|u_ijkd| of the sign tests, ||u_a| - |u_b|| of the magnitude test).
    agree: (K,) bool.  Counts: objects, disagreements beyond the margin
    threshold, objects within it, disagreements within it.
    """

    margin: np.ndarray
    agree: np.ndarray
    threshold_px: float
    n_objects: int
    n_disagree_outside: int
    n_inside: int
    n_disagree_inside: int


def compare_areas(
    pixel_areas: ArrayLike,
    true_areas: ArrayLike,
    u11: ArrayLike,
    u12: ArrayLike,
    u21: ArrayLike,
    u22: ArrayLike,
    u10: float,
    u20: float,
    threshold_px: float = 2.0,
) -> AreaComparison:
    """Count where eq. (12) on pixels disagrees with the truth, split by distance to a boundary."""
    pa, ta = np.asarray(pixel_areas), np.asarray(true_areas)
    d = [np.asarray(u, float) - c for u, c in ((u11, u10), (u12, u10), (u21, u20), (u22, u20))]
    margin = np.min(np.abs(np.stack(d)), axis=0)
    # The magnitude tests: S1/S2 compare step-2 offsets, S3/S4 and S7/S8 step-1 offsets.
    mag_step2 = np.abs(np.abs(d[1]) - np.abs(d[3]))
    mag_step1 = np.abs(np.abs(d[0]) - np.abs(d[2]))
    margin = np.where(
        np.isin(pa, (1, 2)) | np.isin(ta, (1, 2)), np.minimum(margin, mag_step2), margin
    )
    uses_step1 = np.isin(pa, (3, 4, 7, 8)) | np.isin(ta, (3, 4, 7, 8))
    margin = np.where(uses_step1, np.minimum(margin, mag_step1), margin)
    margin = np.where(np.isfinite(margin), margin, 0.0)
    return tally_areas(margin, pa == ta, threshold_px)


def tally_areas(margin: ArrayLike, agree: ArrayLike, threshold_px: float = 2.0) -> AreaComparison:
    """The :class:`AreaComparison` of objects with these margins, px, and agreements."""
    margin, agree = np.asarray(margin, float), np.asarray(agree, bool)
    inside = margin <= threshold_px
    return AreaComparison(
        margin=margin,
        agree=agree,
        threshold_px=threshold_px,
        n_objects=int(agree.size),
        n_disagree_outside=int(np.sum(~agree & ~inside)),
        n_inside=int(np.sum(inside)),
        n_disagree_inside=int(np.sum(~agree & inside)),
    )


def q1_columns(
    z_h: float,
    alpha1: float,
    alpha2: float,
    u211: float,
    u121: float,
    u10: float,
    u20: float,
    baseline: float,
    alpha_e: tuple[float, float] = (0.0, 0.0),
) -> tuple[float, float]:
    """Columns (u21q, u12q), px, of Q1 = (0, 0, z_h) in Ca2's image 1 and Ca1's image 2 (13)-(14).

    Q1 is where the line through the reference P parallel to the baseline meets
    the Z_h axis.  ``beta = atan(2 z_h / D) + alpha1 + alpha_e2 - pi/2`` (13) is
    its angle off Ca2's axis in step 1, and ``u21q - u20 = (u211 - u20) beta /
    (alpha1 - alpha2)`` (14), the reference's offset u211 - u20 standing for
    ``kx (alpha1 - alpha2)``; likewise in Ca1's image 2 with the reference's
    column u121 and angle ``pi/2 - atan(2 z_h / D) - alpha2 - alpha_e1``.
    """
    d = check_baseline(baseline)
    if not (math.isfinite(alpha1 - alpha2) and alpha1 != alpha2):
        raise ValueError("q1_columns needs alpha1 != alpha2 (the reference's two fixations differ)")
    e1, e2 = alpha_e
    base = math.atan(2.0 * z_h / d)
    beta2 = base + alpha1 + e2 - math.pi / 2  # eq. (13)
    beta1 = math.pi / 2 - base - alpha2 - e1
    u21q = u20 + (u211 - u20) * beta2 / (alpha1 - alpha2)  # eq. (14)
    u12q = u10 + (u121 - u10) * beta1 / (alpha1 - alpha2)
    return u21q, u12q


class Q1Side:
    """Which of the four wedges cut by the rays C1-Q1 and C2-Q1 an object is in."""

    UNDECIDED, NEAR, FAR, LEFT, RIGHT = 0, 1, 2, 3, 4


def q1_side(u12: ArrayLike, u21: ArrayLike, u12q: float, u21q: float) -> np.ndarray:
    """Sub-division (K,) by Q1 from objects' columns in Ca1's image 2 and Ca2's image 1, px.

    NEAR: nearer than Q1 (between the rays, baseline side); FAR: beyond Q1;
    LEFT / RIGHT: outside both rays on the -x / +x side.  Combined with the
    area of eq. (12) this splits S3, S4, S5, S6, S9 and S10.
    """
    right_of_c1q1 = np.asarray(u12, float) > u12q
    right_of_c2q1 = np.asarray(u21, float) > u21q
    left_of_c1q1 = np.asarray(u12, float) < u12q
    left_of_c2q1 = np.asarray(u21, float) < u21q
    out = np.full(right_of_c1q1.shape, Q1Side.UNDECIDED)
    out[right_of_c1q1 & left_of_c2q1] = Q1Side.NEAR
    out[left_of_c1q1 & right_of_c2q1] = Q1Side.FAR
    out[left_of_c1q1 & left_of_c2q1] = Q1Side.LEFT
    out[right_of_c1q1 & right_of_c2q1] = Q1Side.RIGHT
    return out
