"""Model 2, the general model without a neck (Sec. II-C, eqs. 4-11), vectorised.

Step 1 turns the eyes until P's image in Ca1 is at column u10 (encoder reading
alpha1); step 2 until P's image in Ca2 is at u20 (alpha2).  With the true yaws
a_i = alpha_i + alpha_ei:

    z_h = D / (tan a1 + tan a2)                            (4)
    x_h = z_h tan a1 - D/2                                 (5)
    x_c1 = z_h sin(alpha1 - gamma1) / cos a1               (8), image at eye angle gamma1
    x_c2 = z_h sin(gamma2 - alpha2) / cos a2               image at eye angle gamma2
    y_ci = (v_id / u_id) (kx_i / ky_i) x_ci                (7), (9), (10)
    y_h = (y_c1 + y_c2) / 2                                (11)

Beyond the paper (docs/equations.md, last section): when each line of sight
misses its yaw axis by s_i (along the effective camera's x), P is the exact
crossing of the two offset lines, and x_c takes the offset too:

    z_h = (D - s1 / cos a1 + s2 / cos a2) / (tan a1 + tan a2)
    x_h = z_h tan a1 + s1 / cos a1 - D/2
    x_c1 = L1 sin(alpha1 - gamma1) + s1 (cos(alpha1 - gamma1) - 1),  L1 = (z_h + s1 sin a1) / cos a1
    x_c2 = L2 sin(gamma2 - alpha2) + s2 (cos(gamma2 - alpha2) - 1),  L2 = (z_h - s2 sin a2) / cos a2

with s_i = 0 these are eqs. (4), (5), (8), (10).

gamma1 = alpha2 and gamma2 = alpha1 are the paper's (u11, v11) and (u21, v21);
gamma = 0 is its near-midline remedy.  The offsets enter only the tangents and
the cos denominators: alpha1 - gamma1 is a relative rotation of one motor.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from headsim.estimators.errors import model2_covariance, model2_jacobian
from headsim.estimators.result import (
    Flag,
    PositionEstimate,
    Uncertainty,
    as_pixels,
    as_vector,
    check_angles,
    check_baseline,
)

__all__ = ["model2"]

_HALF_PI = math.pi / 2


def model2(
    alpha1: ArrayLike,
    alpha2: ArrayLike,
    uv1: ArrayLike,
    uv2: ArrayLike,
    baseline: float,
    *,
    uv10: tuple[float, float],
    uv20: tuple[float, float],
    alpha_e: tuple[float, float] = (0.0, 0.0),
    gamma1: ArrayLike | None = None,
    gamma2: ArrayLike | None = None,
    kx_over_ky: tuple[float, float] = (1.0, 1.0),
    min_abs_ud: float = 1.0,
    uncertainty: Uncertainty | None = None,
    los_offset_m: tuple[float, float] = (0.0, 0.0),
) -> PositionEstimate:
    """Positions of N points in H from Model 2's two fixations.

    alpha1, alpha2: (N,) encoder readings of steps 1 and 2, rad.
    uv1: (N, 2) P's image in Ca1 taken at eye angle gamma1, px; uv2: (N, 2) P's
    image in Ca2 taken at gamma2, px.  gamma1, gamma2: scalar or (N,), rad,
    default alpha2 and alpha1 (the same readings, so their errors are shared).
    baseline: D, m.  uv10, uv20: (u_i0, v_i0) of each camera, px: the servo's
    target column and the reference row (ideally the principal point's v).
    alpha_e: initial directions (alpha_e1, alpha_e2), rad, as calibrated.
    kx_over_ky: the ratio kx_i / ky_i of each camera (eq. 7; 1 if unknown).
    min_abs_ud: |u_id| below this, px, makes eq. (9) or (10) unusable: y_h then
    comes from the other camera alone, or is undetermined if both are.
    uncertainty: input errors for a first-order covariance (N, 3, 3), or None
    (it leaves out the offsets' small effect).
    los_offset_m: (s1, s2), m: how far each goal column's line of sight misses
    its eye's yaw axis, along the camera's x (as calibrated; 0 is the paper's eye).

    Per-point degeneracies are flagged (``valid`` False, positions NaN), not
    raised; wrong shapes and angles that are not radians raise ValueError.
    """
    a1_enc = as_vector(alpha1, "alpha1")
    n = a1_enc.shape[0]
    a2_enc = as_vector(alpha2, "alpha2")
    if a2_enc.shape != (n,):
        raise ValueError(f"alpha2 must have shape ({n},) like alpha1, got {a2_enc.shape}")
    uv1 = as_pixels(uv1, "uv1", n)
    uv2 = as_pixels(uv2, "uv2", n)
    g1 = a2_enc if gamma1 is None else _gamma(gamma1, "gamma1", n)
    g2 = a1_enc if gamma2 is None else _gamma(gamma2, "gamma2", n)
    for name, a in (("alpha1", a1_enc), ("alpha2", a2_enc), ("gamma1", g1), ("gamma2", g2)):
        check_angles(a, name)
    d = check_baseline(baseline)
    e1, e2 = (float(e) for e in alpha_e)
    check_angles(np.array([e1, e2]), "alpha_e")
    r1, r2 = (float(r) for r in kx_over_ky)
    if not (r1 > 0.0 and r2 > 0.0 and math.isfinite(r1) and math.isfinite(r2)):
        raise ValueError(f"kx_over_ky must be two positive ratios, got {kx_over_ky!r}")
    o1, o2 = (float(o) for o in los_offset_m)
    if not (math.isfinite(o1) and math.isfinite(o2) and abs(o1) < d / 2 and abs(o2) < d / 2):
        raise ValueError(
            f"los_offset_m must be two offsets in metres, |s| < D/2, got {los_offset_m!r}"
        )
    if not min_abs_ud >= 0.0:
        raise ValueError(f"min_abs_ud must be >= 0 px, got {min_abs_ud!r}")

    a1, a2 = a1_enc + e1, a2_enc + e2
    t1, t2 = np.tan(a1), np.tan(a2)
    s = t1 + t2
    sec1, sec2 = np.sqrt(1.0 + t1 * t1), np.sqrt(1.0 + t2 * t2)  # 1/cos a_i for |a_i| < pi/2
    with np.errstate(divide="ignore", invalid="ignore"):
        if o1 == 0.0 and o2 == 0.0:
            z = d / s
            x = z * t1 - 0.5 * d
        else:
            z = (d - o1 * sec1 + o2 * sec2) / s
            x = z * t1 + o1 * sec1 - 0.5 * d
        sin1, cos1 = _sin_cos(a1_enc - g1)
        if gamma1 is None and gamma2 is None:
            sin2, cos2 = sin1, cos1  # gamma2 - alpha2 = alpha1 - alpha2 = alpha1 - gamma1
        else:
            sin2, cos2 = _sin_cos(g2 - a2_enc)
        u1d, v1d = uv1[:, 0] - uv10[0], uv1[:, 1] - uv10[1]
        u2d, v2d = uv2[:, 0] - uv20[0], uv2[:, 1] - uv20[1]
        if o1 == 0.0 and o2 == 0.0:
            xc1, xc2 = z * sin1 * sec1, z * sin2 * sec2
        else:
            # L1 = z sec a1 + s1 tan a1, L2 = z sec a2 - s2 tan a2.
            xc1 = (z * sec1 + o1 * t1) * sin1 + o1 * (cos1 - 1.0)
            xc2 = (z * sec2 - o2 * t2) * sin2 + o2 * (cos2 - 1.0)
        y1 = (r1 * v1d / u1d) * xc1
        y2 = (r2 * v2d / u2d) * xc2

    finite = (
        np.isfinite(a1)
        & np.isfinite(a2)
        & np.isfinite(g1)
        & np.isfinite(g2)
        & np.isfinite(u1d)  # column-wise: isfinite(uv).all(axis=1) is 30x slower
        & np.isfinite(v1d)
        & np.isfinite(u2d)
        & np.isfinite(v2d)
    )
    small1 = ~(np.abs(u1d) >= min_abs_ud)
    small2 = ~(np.abs(u2d) >= min_abs_ud)
    flags = np.zeros(n, dtype=np.int64)
    flags[~finite] |= Flag.NONFINITE
    flags[~(s > 0.0) & finite] |= Flag.NOT_CONVERGING
    behind = (np.abs(a1) >= _HALF_PI) | (np.abs(a2) >= _HALF_PI) | (cos1 <= 0.0) | (cos2 <= 0.0)
    flags[behind & finite] |= Flag.BEHIND_CAMERA
    flags[small1 & finite] |= Flag.SMALL_U1D
    flags[small2 & finite] |= Flag.SMALL_U2D
    flags[small1 & small2 & finite] |= Flag.NO_Y
    valid = (flags & Flag.fatal()) == 0

    w1 = np.where(small1, 0.0, np.where(small2, 1.0, 0.5))
    w2 = np.where(small2, 0.0, np.where(small1, 1.0, 0.5))
    y = np.where(small1, 0.0, w1 * y1) + np.where(small2, 0.0, w2 * y2)
    positions = np.stack([x, y, z], axis=-1)
    positions[~valid] = np.nan
    y_cam = np.stack([np.where(small1, np.nan, y1), np.where(small2, np.nan, y2)], axis=-1)
    y_cam[~valid] = np.nan

    covariance = None
    if uncertainty is not None:
        safe1 = np.stack([np.where(small1, 1.0, u1d), v1d], axis=-1)
        safe2 = np.stack([np.where(small2, 1.0, u2d), v2d], axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            jac = model2_jacobian(
                a1_enc, a2_enc, g1, g2, safe1, safe2, d, (e1, e2), (r1, r2), (w1, w2)
            )
            covariance = model2_covariance(
                jac, uncertainty, tied_gammas=(gamma1 is None, gamma2 is None)
            )
        covariance[~valid] = np.nan
    return PositionEstimate(positions, valid, flags, covariance, y_cam)


def _gamma(gamma: ArrayLike, name: str, n: int) -> np.ndarray:
    g = np.asarray(gamma, dtype=float)
    if g.ndim == 0:
        return np.full(n, float(g))
    if g.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have shape ({n},), got {g.shape}")
    return g


def _sin_cos(angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sin and a value with the sign of cos, from one tan (np.sin/np.cos are slow for float64)."""
    t = np.tan(angle)
    c = np.sqrt(1.0 + t * t)
    sign = np.where(np.abs(angle) < _HALF_PI, 1.0, -1.0)  # angle within (-pi, pi] by the checks
    return sign * t / c, sign / c
