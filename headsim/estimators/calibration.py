"""Calibration of the initial directions alpha_e1, alpha_e2 (Sec. V, eqs. 22-26).

A target at known depth z_h is fixated with Model 2 at n places, giving
(alpha1, alpha2, z_h) per sample.  With x = tan alpha_e1, y = tan alpha_e2,
t_i = tan alpha_i and K = D / z_h, eq. (22) tan(alpha1 + alpha_e1) +
tan(alpha2 + alpha_e2) = K becomes f = a1 x y + a2 x + a3 y + a4 = 0 (23), (24);
F = sum f_i^2 (25), (26) is minimised.  The paper uses a quasi-Newton method; F is
a sum of squares of residuals bilinear in (x, y), so damped Gauss-Newton steps
(Levenberg-Marquardt) reach the same minimum, certified by an undamped step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from headsim.estimators.result import as_vector, check_angles, check_baseline

__all__ = [
    "Calibration",
    "LineOfSightCalibration",
    "calibrate_initial_directions",
    "calibrate_lines_of_sight",
    "calibration_coefficients",
    "line_of_sight_residuals",
]


@dataclass(frozen=True)
class Calibration:
    """Result of :func:`calibrate_initial_directions`.

    alpha_e: (2,) the initial directions (alpha_e1, alpha_e2), rad.
    std_errors: (2,) their standard errors, rad (NaN when n = 2 and no noise model).
    covariance: (2, 2) rad^2.  residuals: (n,) f_i of eq. (25) at the solution.
    depth_residuals: (n,) D / (tan a1 + tan a2) - z_h, m.  weighted: whether a
    noise model weighted the samples.  converged, message: from the optimiser.
    """

    alpha_e: np.ndarray
    std_errors: np.ndarray
    covariance: np.ndarray
    residuals: np.ndarray
    depth_residuals: np.ndarray
    weighted: bool
    converged: bool
    message: str


def calibration_coefficients(
    alpha1: np.ndarray, alpha2: np.ndarray, z_h: np.ndarray, baseline: float
) -> np.ndarray:
    """Coefficients (n, 4) = (a1, a2, a3, a4) of eq. (24) per sample."""
    t1, t2, k = np.tan(alpha1), np.tan(alpha2), baseline / z_h
    return np.stack(
        [t1 + t2 + t1 * t2 * k, t1 * t2 - t1 * k - 1.0, t1 * t2 - t2 * k - 1.0, k - t1 - t2], -1
    )


def calibrate_initial_directions(
    alpha1: ArrayLike,
    alpha2: ArrayLike,
    z_h: ArrayLike,
    baseline: float,
    *,
    sigma_encoder: float | None = None,
    sigma_depth: float | None = None,
    initial: tuple[float, float] = (0.0, 0.0),
) -> Calibration:
    """Initial directions from n >= 2 samples of (alpha1, alpha2) (rad) at known depth z_h (m).

    Without a noise model the paper's unweighted F is minimised and the
    covariance is s^2 (J^T J)^-1 with s^2 = F / (n - 2).  With ``sigma_encoder``
    (rad, per reading) and/or ``sigma_depth`` (m, per z_h) each f_i is weighted
    by the inverse of its first-order variance at the solution (one
    re-weighting pass) and the covariance is (J^T W J)^-1.  Raises ValueError
    for fewer than two usable samples, non-finite input, or samples that do
    not separate the two offsets.
    """
    a1, a2, z = as_vector(alpha1, "alpha1"), as_vector(alpha2, "alpha2"), as_vector(z_h, "z_h")
    if not (a1.shape == a2.shape == z.shape):
        raise ValueError(
            f"alpha1, alpha2, z_h must have one shape (n,), got {a1.shape}, {a2.shape}, {z.shape}"
        )
    if a1.size < 2:
        raise ValueError(f"calibration needs at least two samples, got {a1.size}")
    if not (np.isfinite(a1).all() and np.isfinite(a2).all() and np.isfinite(z).all()):
        raise ValueError("calibration samples must be finite (NaN or inf in alpha1, alpha2 or z_h)")
    check_angles(a1, "alpha1")
    check_angles(a2, "alpha2")
    if not (z > 0.0).all():
        raise ValueError("z_h must be > 0 m for every sample (a target behind the cameras)")
    d = check_baseline(baseline)
    coeffs = calibration_coefficients(a1, a2, z, d)
    weighted = sigma_encoder is not None or sigma_depth is not None
    se, sd = float(sigma_encoder or 0.0), float(sigma_depth or 0.0)
    if weighted and not (se >= 0.0 and sd >= 0.0 and se + sd > 0.0):
        raise ValueError(f"sigma_encoder, sigma_depth must be >= 0 and not both 0, got {se}, {sd}")

    w = np.ones(a1.size)
    xy = np.tan(np.asarray(initial, dtype=float))
    for _ in range(2 if weighted else 1):
        xy, ok, message = _minimise(coeffs, w, xy)
        if weighted:
            w = 1.0 / _residual_variance(a1, a2, z, d, xy, se, sd)
    f, jac = _residuals(coeffs, xy)
    jtwj = jac.T @ (w[:, None] * jac)
    if np.linalg.cond(jtwj) > 1e12:
        raise ValueError(
            "the samples do not separate alpha_e1 from alpha_e2 (J^T J is singular): "
            "place the target at several lateral positions and depths"
        )
    cov_xy = np.linalg.inv(jtwj)
    if not weighted:
        dof = a1.size - 2
        cov_xy = cov_xy * (float(f @ f) / dof if dof > 0 else np.nan)
    to_angle = np.diag(1.0 / (1.0 + xy * xy))  # d atan(x) / dx
    cov = to_angle @ cov_xy @ to_angle
    alpha_e = np.arctan(xy)
    z_model = d / (np.tan(a1 + alpha_e[0]) + np.tan(a2 + alpha_e[1]))
    return Calibration(
        alpha_e=alpha_e,
        std_errors=np.sqrt(np.diag(cov)),
        covariance=cov,
        residuals=f,
        depth_residuals=z_model - z,
        weighted=weighted,
        converged=ok,
        message=message,
    )


def _residuals(coeffs: np.ndarray, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """f_i (n,) of eq. (25) and their Jacobian (n, 2) w.r.t. (x, y)."""
    x, y = xy
    a1, a2, a3, a4 = coeffs.T
    f = a1 * x * y + a2 * x + a3 * y + a4
    return f, np.stack([a1 * y + a2, a1 * x + a3], axis=-1)


def _minimise(coeffs: np.ndarray, w: np.ndarray, start: np.ndarray) -> tuple[np.ndarray, bool, str]:
    """Levenberg-Marquardt on F = sum w_i f_i^2 from ``start``.

    Each iteration solves the normal equations with the diagonal scaled by
    1 + ``damping``; a step that lowers F is taken and the damping falls, else it
    grows.  Converged when the undamped Gauss-Newton step is below 1e-13 (tangent
    of an angle): F is then at its minimum to rounding.  Bounded by
    :data:`MAX_ITERATIONS`; the message says how it ended.  (It was scipy's BFGS,
    certified by the same step: the same minimum, without 0.4 s of importing
    ``scipy.optimize`` in every process that calibrates.)
    """
    xy = np.asarray(start, dtype=float)
    f, jac = _residuals(coeffs, xy)
    cost = float(np.sum(w * f * f))
    damping = 1e-3
    for iteration in range(1, MAX_ITERATIONS + 1):
        normal = jac.T @ (w[:, None] * jac)
        gradient = jac.T @ (w * f)
        try:
            step = np.linalg.solve(normal, -gradient)
            size = float(np.max(np.abs(step)))
            if size < 1e-13:
                return xy + step, True, f"converged in {iteration} iterations"
            damped = np.linalg.solve(normal + damping * np.diag(np.diag(normal)), -gradient)
        except np.linalg.LinAlgError:
            return xy, False, f"singular normal equations after {iteration} iterations"
        if size < POLISH_STEP:
            # So close that F cannot tell better from worse in floating point: the
            # undamped steps, which shrink towards the minimum.
            xy = xy + step
            f, jac = _residuals(coeffs, xy)
            cost = float(np.sum(w * f * f))
            continue
        f_new, jac_new = _residuals(coeffs, xy + damped)
        cost_new = float(np.sum(w * f_new * f_new))
        if cost_new <= cost:
            xy, f, jac, cost = xy + damped, f_new, jac_new, cost_new
            damping = max(0.1 * damping, 1e-15)
        else:
            damping *= 10.0
            if damping > 1e15:
                return xy, False, f"no step lowers F after {iteration} iterations"
    return xy, False, f"not converged in {MAX_ITERATIONS} iterations"


#: Iterations of :func:`_minimise` at most.
MAX_ITERATIONS = 200
#: Below this Gauss-Newton step (tangent of an angle) :func:`_minimise` takes it undamped.
POLISH_STEP = 1e-8


def _residual_variance(
    a1: np.ndarray, a2: np.ndarray, z: np.ndarray, d: float, xy: np.ndarray, se: float, sd: float
) -> np.ndarray:
    """First-order variance (n,) of f_i from encoder errors (rad) and depth errors (m)."""
    x, y = xy
    t1, t2, k = np.tan(a1), np.tan(a2), d / z
    df_dt1 = (1.0 + t2 * k) * x * y + (t2 - k) * x + t2 * y - 1.0
    df_dt2 = (1.0 + t1 * k) * x * y + t1 * x + (t1 - k) * y - 1.0
    df_dk = t1 * t2 * x * y - t1 * x - t2 * y + 1.0
    var_enc = ((df_dt1 * (1.0 + t1 * t1)) ** 2 + (df_dt2 * (1.0 + t2 * t2)) ** 2) * se**2
    return var_enc + (df_dk * k * sd / z) ** 2 + math.ulp(1.0)


# -- Beyond the paper: each line of sight's offset from its yaw axis -------------


@dataclass(frozen=True)
class LineOfSightCalibration:
    """Result of :func:`calibrate_lines_of_sight`.

    alpha_e: (2,) initial directions (alpha_e1, alpha_e2), rad.  offset_m: (2,)
    (s1, s2), how far each goal column's line of sight misses its believed
    yaw axis, m, along the camera's x (it takes in the baseline's error too).
    std_errors: (4,) of (alpha_e1, alpha_e2, s1, s2).  covariance: (4, 4).
    effective_baseline_m: D - s1 + s2 (the lines' separation at small angles),
    with its standard error.  separable: whether the layout separates each
    offset from its direction; message: why not, or "ok".
    residuals_m: (n, 2) each target's distance from the two fitted lines.
    """

    alpha_e: np.ndarray
    offset_m: np.ndarray
    std_errors: np.ndarray
    covariance: np.ndarray
    effective_baseline_m: float
    effective_baseline_std_m: float
    separable: bool
    message: str
    residuals_m: np.ndarray


def line_of_sight_residuals(
    params: np.ndarray,
    alpha1: np.ndarray,
    alpha2: np.ndarray,
    x_h: np.ndarray,
    z_h: np.ndarray,
    baseline: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Residuals (n, 2), their Jacobian (n, 2, 4) and ranges along each line (n, 2).

    params = (alpha_e1, alpha_e2, s1, s2).  Ca1's line through the axis at
    (-D/2, 0) with direction a1 = alpha1 + alpha_e1 holds P when
    (x + D/2) cos a1 - z sin a1 = s1; Ca2's when (x - D/2) cos a2 + z sin a2 = s2.
    """
    e1, e2, s1, s2 = params
    a1, a2 = alpha1 + e1, alpha2 + e2
    x1, x2 = x_h + baseline / 2.0, x_h - baseline / 2.0
    c1, n1, c2, n2 = np.cos(a1), np.sin(a1), np.cos(a2), np.sin(a2)
    r = np.stack([x1 * c1 - z_h * n1 - s1, x2 * c2 + z_h * n2 - s2], axis=-1)
    range1, range2 = x1 * n1 + z_h * c1, -x2 * n2 + z_h * c2
    jac = np.zeros((alpha1.size, 2, 4))
    jac[:, 0, 0], jac[:, 0, 2] = -range1, -1.0
    jac[:, 1, 1], jac[:, 1, 3] = range2, -1.0
    return r, jac, np.stack([range1, range2], axis=-1)


def calibrate_lines_of_sight(
    alpha1: ArrayLike,
    alpha2: ArrayLike,
    positions_h: ArrayLike,
    baseline: float,
    *,
    sigma_position: float,
    sigma_encoder: float,
    initial: tuple[float, float] = (0.0, 0.0),
    max_iterations: int = 50,
) -> LineOfSightCalibration:
    """Initial directions and line-of-sight offsets from fixations of targets at measured positions.

    alpha1, alpha2: (n,) Model 2's fixation readings, rad; positions_h: (n, 3)
    the targets' measured positions in H, m (a tape measure: Gaussian error
    ``sigma_position`` m on each coordinate); baseline: the believed D, m;
    sigma_encoder: error of each fixation angle, rad.  Weighted Gauss-Newton
    with each target's 2 x 2 residual covariance (x and z errors are shared by
    both lines); covariance (J^T W J)^-1.  Raises ValueError for fewer than
    three targets, non-finite input or non-positive sigmas.
    """
    a1, a2 = as_vector(alpha1, "alpha1"), as_vector(alpha2, "alpha2")
    p = np.asarray(positions_h, dtype=float)
    if p.shape != (a1.size, 3) or a2.shape != a1.shape:
        raise ValueError(
            f"alpha1, alpha2 (n,) and positions_h (n, 3) must agree, got "
            f"{a1.shape}, {a2.shape}, {p.shape}"
        )
    if a1.size < 3:
        raise ValueError(f"the line-of-sight fit needs at least 3 targets, got {a1.size}")
    if not (np.isfinite(a1).all() and np.isfinite(a2).all() and np.isfinite(p).all()):
        raise ValueError("line-of-sight samples must be finite (NaN or inf in angles or positions)")
    check_angles(a1, "alpha1")
    check_angles(a2, "alpha2")
    d = check_baseline(baseline)
    if not (sigma_position > 0.0 and sigma_encoder >= 0.0):
        raise ValueError(
            f"sigma_position must be > 0 m and sigma_encoder >= 0 rad, "
            f"got {sigma_position!r}, {sigma_encoder!r}"
        )
    x, z = p[:, 0], p[:, 2]
    params = np.array([initial[0], initial[1], 0.0, 0.0])
    message = f"did not settle in {max_iterations} Gauss-Newton steps"
    settled = False
    for _ in range(max_iterations):
        r, jac, ranges = line_of_sight_residuals(params, a1, a2, x, z, d)
        weight = _los_weights(params, a1, a2, ranges, sigma_position, sigma_encoder)
        jtw = np.einsum("nij,nik->njk", jac, weight)  # (n, 4, 2)
        normal = np.einsum("njk,nkl->jl", jtw, jac)
        gradient = np.einsum("njk,nk->j", jtw, r)
        try:
            step = np.linalg.solve(normal, -gradient)
        except np.linalg.LinAlgError:
            message = "singular normal equations"
            break
        params = params + step
        if np.max(np.abs(step)) < 1e-14:
            settled = True
            message = "ok"
            break
    r, jac, ranges = line_of_sight_residuals(params, a1, a2, x, z, d)
    weight = _los_weights(params, a1, a2, ranges, sigma_position, sigma_encoder)
    normal = np.einsum("nij,nik,nkl->jl", jac, weight, jac)
    cond = np.linalg.cond(normal)
    spread = float(np.min(np.std(ranges, axis=0) / np.mean(np.abs(ranges), axis=0)))
    separable = bool(cond < 1e12 and spread > 0.05 and settled)
    if not separable and settled:
        message = (
            f"the targets' ranges along the lines of sight vary by {spread:.1%} only: the "
            "layout cannot separate each offset from its direction; spread the targets in depth"
        )
    covariance = np.linalg.pinv(normal)
    std = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    grad_b = np.array([0.0, 0.0, -1.0, 1.0])
    return LineOfSightCalibration(
        alpha_e=params[:2].copy(),
        offset_m=params[2:].copy(),
        std_errors=std,
        covariance=covariance,
        effective_baseline_m=float(d - params[2] + params[3]),
        effective_baseline_std_m=float(np.sqrt(max(grad_b @ covariance @ grad_b, 0.0))),
        separable=separable,
        message=message,
        residuals_m=r,
    )


def _los_weights(
    params: np.ndarray,
    a1: np.ndarray,
    a2: np.ndarray,
    ranges: np.ndarray,
    sigma_position: float,
    sigma_encoder: float,
) -> np.ndarray:
    """Inverse (n, 2, 2) of each target's residual covariance."""
    t1, t2 = a1 + params[0], a2 + params[1]
    cov = np.empty((a1.size, 2, 2))
    var_p = sigma_position**2
    cov[:, 0, 0] = var_p + (ranges[:, 0] * sigma_encoder) ** 2
    cov[:, 1, 1] = var_p + (ranges[:, 1] * sigma_encoder) ** 2
    cov[:, 0, 1] = cov[:, 1, 0] = var_p * np.cos(t1 + t2)  # x: cos a1 cos a2; z: -sin a1 sin a2
    return np.linalg.inv(cov)
