"""Error propagation: the paper's formulas (15)-(21) and a general first-order covariance.

The paper's formulas take the angles as the paper writes them (encoder reading
= true yaw, i.e. calibrated offsets already added) and return relative errors
(dimensionless, ``dz/z`` etc.) for given signed input errors.  The general
covariance propagates independent standard deviations of D (m), of every
encoder reading (rad) and of every pixel coordinate (px) through the exact
Jacobian of Model 1 (eq. 2) or Model 2 (eqs. 4-11) to (x_h, y_h, z_h) in H.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from headsim.estimators.result import Uncertainty

__all__ = [
    "MODEL2_PARAMETERS",
    "model1_covariance",
    "model2_covariance",
    "model2_jacobian",
    "rel_dx_model2",
    "rel_dy_model2",
    "rel_dy_model2_simplified",
    "rel_dz_correspondence",
    "rel_dz_model1",
    "rel_dz_model1_small_angle",
    "rel_dz_model2",
    "rel_dz_model2_small_angle",
]

#: Order of the inputs in :func:`model2_jacobian`'s last axis.
MODEL2_PARAMETERS = ("D", "alpha1", "alpha2", "gamma1", "gamma2", "u1", "v1", "u2", "v2")


def rel_dz_model1(alpha: ArrayLike, rel_dD: ArrayLike, dalpha: ArrayLike) -> np.ndarray:
    """Eq. (15): dz/z = dD/D - 2 dalpha / sin(2 alpha)."""
    return np.asarray(rel_dD) - 2.0 * np.asarray(dalpha) / np.sin(2.0 * np.asarray(alpha))


def rel_dz_model1_small_angle(alpha: ArrayLike, rel_dD: ArrayLike, dalpha: ArrayLike) -> np.ndarray:
    """Eq. (16): dz/z ~ dD/D - dalpha / alpha."""
    return np.asarray(rel_dD) - np.asarray(dalpha) / np.asarray(alpha)


def rel_dz_model2(
    a1: ArrayLike, a2: ArrayLike, rel_dD: ArrayLike, da1: ArrayLike, da2: ArrayLike
) -> np.ndarray:
    """Eq. (17): dz/z = dD/D - [(cos a2/cos a1) da1 + (cos a1/cos a2) da2] / sin(a1 + a2)."""
    a1, a2 = np.asarray(a1, float), np.asarray(a2, float)
    c1, c2 = np.cos(a1), np.cos(a2)
    return np.asarray(rel_dD) - (c2 / c1 * np.asarray(da1) + c1 / c2 * np.asarray(da2)) / np.sin(
        a1 + a2
    )


def rel_dz_model2_small_angle(
    a1: ArrayLike, a2: ArrayLike, rel_dD: ArrayLike, da1: ArrayLike, da2: ArrayLike
) -> np.ndarray:
    """Eq. (18): dz/z ~ dD/D - d(a1 + a2) / (a1 + a2)."""
    return np.asarray(rel_dD) - (np.asarray(da1) + np.asarray(da2)) / (
        np.asarray(a1) + np.asarray(a2)
    )


def rel_dz_correspondence(
    a1: ArrayLike, a2: ArrayLike, du2_px: ArrayLike, f2_px: ArrayLike
) -> np.ndarray:
    """docs/equations.md (M5): dz/z from a correspondence error ``du2_px`` in camera 2
    (eye 2 turned by du2 / f2), eq. (17) with dD = da1 = 0."""
    return rel_dz_model2(a1, a2, 0.0, 0.0, np.asarray(du2_px, float) / np.asarray(f2_px, float))


def rel_dx_model2(
    a1: ArrayLike, rel_dz: ArrayLike, dD: ArrayLike, z: ArrayLike, da1: ArrayLike
) -> np.ndarray:
    """Eq. (19): dx/z = (dz/z) tan a1 - dD/(2 z) + da1 / cos^2 a1; dD and z in m."""
    a1 = np.asarray(a1, float)
    return (
        np.asarray(rel_dz) * np.tan(a1)
        - np.asarray(dD) / (2.0 * np.asarray(z))
        + np.asarray(da1) / np.cos(a1) ** 2
    )


def rel_dy_model2(
    a1: ArrayLike,
    a2: ArrayLike,
    u1d: ArrayLike,
    v1d: ArrayLike,
    u2d: ArrayLike,
    v2d: ArrayLike,
    rel_dz: ArrayLike,
    da1: ArrayLike = 0.0,
    da2: ArrayLike = 0.0,
    du1d: ArrayLike = 0.0,
    dv1d: ArrayLike = 0.0,
    du2d: ArrayLike = 0.0,
    dv2d: ArrayLike = 0.0,
) -> np.ndarray:
    """Eq. (20): dy/z of y_h = (y_c1 + y_c2)/2 of eqs. (9)-(11); pixel offsets and errors in px."""
    a1, a2 = np.asarray(a1, float), np.asarray(a2, float)
    u1d, v1d, u2d, v2d = (np.asarray(q, float) for q in (u1d, v1d, u2d, v2d))
    da1, da2, rel_dz = np.asarray(da1), np.asarray(da2), np.asarray(rel_dz)
    s, c, c1, c2 = np.sin(a1 - a2), np.cos(a1 - a2), np.cos(a1), np.cos(a2)
    cam1 = v1d / u1d * (s / c1 * rel_dz + (c2 * da1 - c * c1 * da2) / c1**2)
    cam2 = v2d / u2d * (s / c2 * rel_dz + (c * c2 * da1 - c1 * da2) / c2**2)
    pix = (np.asarray(dv1d) / u1d - v1d * np.asarray(du1d) / u1d**2) * s / c1 + (
        np.asarray(dv2d) / u2d - v2d * np.asarray(du2d) / u2d**2
    ) * s / c2
    return 0.5 * (cam1 + cam2 + pix)


def rel_dy_model2_simplified(
    a1: ArrayLike,
    a2: ArrayLike,
    u1d: ArrayLike,
    v1d: ArrayLike,
    u2d: ArrayLike,
    v2d: ArrayLike,
    rel_dz: ArrayLike,
    dv1d: ArrayLike = 0.0,
    dv2d: ArrayLike = 0.0,
) -> np.ndarray:
    """Eq. (21): eq. (20) without the angle and du terms; pixel offsets and errors in px."""
    a1, a2 = np.asarray(a1, float), np.asarray(a2, float)
    g1 = np.sin(a1 - a2) / np.cos(a1)
    g2 = np.sin(a1 - a2) / np.cos(a2)
    v_over_u = np.asarray(v1d) / np.asarray(u1d) * g1 + np.asarray(v2d) / np.asarray(u2d) * g2
    dv_over_u = np.asarray(dv1d) / np.asarray(u1d) * g1 + np.asarray(dv2d) / np.asarray(u2d) * g2
    return 0.5 * (v_over_u * np.asarray(rel_dz) + dv_over_u)


def model1_covariance(
    alpha_true: np.ndarray, baseline: float, uncertainty: Uncertainty
) -> np.ndarray:
    """Covariance (N, 3, 3), m^2, of Model 1's (0, 0, z_h) from D and the eye encoder.

    ``alpha_true``: (N,) true yaw alpha + alpha_e, rad.  x_h = y_h = 0 by the servo
    and carry no variance here.
    """
    z = baseline / (2.0 * np.tan(alpha_true))
    dz_dd = z / baseline
    dz_da = -2.0 * z / np.sin(2.0 * alpha_true)
    cov = np.zeros((*z.shape, 3, 3))
    cov[..., 2, 2] = (dz_dd * uncertainty.baseline) ** 2 + (dz_da * uncertainty.encoder) ** 2
    return cov


def model2_jacobian(
    alpha1: np.ndarray,
    alpha2: np.ndarray,
    gamma1: np.ndarray,
    gamma2: np.ndarray,
    uv1d: np.ndarray,
    uv2d: np.ndarray,
    baseline: float,
    alpha_e: tuple[float, float] = (0.0, 0.0),
    kx_over_ky: tuple[float, float] = (1.0, 1.0),
    y_weights: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """Jacobian (N, 3, 9) of Model 2's (x_h, y_h, z_h) w.r.t. :data:`MODEL2_PARAMETERS`.

    alpha1, alpha2, gamma1, gamma2: (N,) encoder readings, rad; uv1d, uv2d: (N, 2)
    pixel offsets (u - u_i0, v - v_i0) of the y images, px.  ``y_weights``: the
    weights (N,) of y_c1 and y_c2 in y_h (default 1/2 each).  The gamma columns
    are those of separate readings; where gamma1 *is* alpha2 (the default
    images) add column 3 to column 2 (and column 4 to column 1).
    """
    e1, e2 = alpha_e
    t1, t2 = np.tan(alpha1 + e1), np.tan(alpha2 + e2)
    sec1, sec2 = np.sqrt(1.0 + t1 * t1), np.sqrt(1.0 + t2 * t2)  # 1 / cos a_i
    s = t1 + t2
    z = baseline / s
    dz = (z / baseline, -z * sec1**2 / s, -z * sec2**2 / s)  # d z / d(D, alpha1, alpha2)
    dx = (dz[0] * t1 - 0.5, dz[1] * t1 + z * sec1**2, dz[2] * t1)  # eq. (5)
    sd1, cd1 = np.sin(alpha1 - gamma1), np.cos(alpha1 - gamma1)
    sd2, cd2 = np.sin(gamma2 - alpha2), np.cos(gamma2 - alpha2)
    xc1, xc2 = z * sd1 * sec1, z * sd2 * sec2  # eq. (8) and its Ca2 twin
    # d x_c1 / d(D, alpha1, alpha2, gamma1) and d x_c2 / d(D, alpha1, alpha2, gamma2)
    dxc1 = (
        xc1 / baseline,
        dz[1] * sd1 * sec1 + z * sec1 * (cd1 + sd1 * t1),
        dz[2] * sd1 * sec1,
        -z * cd1 * sec1,
    )
    dxc2 = (
        xc2 / baseline,
        dz[1] * sd2 * sec2,
        dz[2] * sd2 * sec2 + z * sec2 * (sd2 * t2 - cd2),
        z * cd2 * sec2,
    )
    n = alpha1.shape[0]
    w1, w2 = (np.broadcast_to(np.asarray(w, float), (n,)) for w in (y_weights or (0.5, 0.5)))
    # y_h = w1 q1 x_c1 + w2 q2 x_c2 with q_i = (kx_i / ky_i) v_id / u_id, eqs. (7), (9)-(11)
    p1, p2 = w1 * kx_over_ky[0] / uv1d[:, 0], w2 * kx_over_ky[1] / uv2d[:, 0]
    q1, q2 = p1 * uv1d[:, 1], p2 * uv2d[:, 1]
    jac = np.zeros((n, 3, 9))
    for k in range(3):
        jac[:, 0, k] = dx[k]
        jac[:, 2, k] = dz[k]
        jac[:, 1, k] = q1 * dxc1[k] + q2 * dxc2[k]
    jac[:, 1, 3] = q1 * dxc1[3]
    jac[:, 1, 4] = q2 * dxc2[3]
    jac[:, 1, 5] = -q1 * xc1 / uv1d[:, 0]
    jac[:, 1, 6] = p1 * xc1
    jac[:, 1, 7] = -q2 * xc2 / uv2d[:, 0]
    jac[:, 1, 8] = p2 * xc2
    return jac


def model2_covariance(
    jacobian: np.ndarray, uncertainty: Uncertainty, *, tied_gammas: tuple[bool, bool] = (True, True)
) -> np.ndarray:
    """Covariance (N, 3, 3), m^2, from a :func:`model2_jacobian` and independent input errors.

    ``tied_gammas``: whether gamma1 is the step-2 reading alpha2 itself (and
    gamma2 the step-1 reading alpha1), so their errors are one and the same.
    """
    jac = jacobian.copy()
    var = np.array(
        [uncertainty.baseline**2] + [uncertainty.encoder**2] * 4 + [uncertainty.pixel**2] * 4
    )
    if tied_gammas[0]:
        jac[..., 2] += jac[..., 3]
        var[3] = 0.0
    if tied_gammas[1]:
        jac[..., 1] += jac[..., 4]
        var[4] = 0.0
    return np.einsum("nip,njp->nij", jac * var, jac)
