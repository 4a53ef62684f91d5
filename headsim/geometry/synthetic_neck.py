"""Exact forward model of Model 1 (Sec. II-B): the neck and eye angles that fixate a point.

The neck puts P in the plane of the optical axes and the eyes verge until both
images lie at their target columns.  Frames and signs as in docs/equations.md and
:mod:`headsim.geometry.synthetic`: points in W or H, m; angles rad, eye angles
positive inwards.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from headsim.geometry._roots import solve_increasing
from headsim.geometry.synthetic import StereoHead, effective_initial_direction, quantise

__all__ = ["NeckFixation", "neck_fixation"]


@dataclass(frozen=True)
class NeckFixation:
    """Model 1's servo result for N points: neck angles, eye angle and the point in the new H.

    theta1, theta2: (N,) neck yaw and pitch, rad; alpha: (N,) eye angle, rad;
    points_h: (N, 3) the point in the fixated head frame, m; valid: (N,) False
    where no fixation exists (angles NaN).
    """

    theta1: np.ndarray
    theta2: np.ndarray
    alpha: np.ndarray
    points_h: np.ndarray
    valid: np.ndarray


def neck_fixation(
    head: StereoHead, points_w: ArrayLike, d1: float, a2: float, *, quantised: bool = False
) -> NeckFixation:
    """Neck and eye angles that fixate points (N, 3) in W with Model 1, exactly.

    The neck puts P in the plane of the optical axes (y_h = 0, so P images on
    the principal row) and the single eye angle alpha puts P on both target
    columns, i.e. at the crossing of the two effective lines of sight; with
    equal effective initial directions that crossing is on the Z_h axis.  With
    y_h = 0, |P_h| is the same for every neck pose, so it fixes alpha (1-D
    solve), then theta2 and theta1 follow in closed form.  With ``quantised`` only alpha is rounded
    to the encoder (the neck angles and the point stay those of the exact
    fixation); quantise the neck yourself with :func:`quantise`.  The optical
    centres' offsets (``nodal*``, ``side*``) are not modelled here (Model 2's
    functions cover them); yaw-axis tilt is modelled nowhere in this module.
    """
    pw = np.asarray(points_w, dtype=float)
    if pw.ndim != 2 or pw.shape[1] != 3:
        raise ValueError(f"points_w must have shape (N, 3), got {pw.shape}")
    u10, u20 = head.target_columns
    e1 = effective_initial_direction(1, head.alpha_e1, head.cam1, u10, head.cam1.cy)
    e2 = effective_initial_direction(2, head.alpha_e2, head.cam2, u20, head.cam2.cy)
    half = head.baseline / 2.0
    h = pw[:, 2] - d1
    rho2 = pw[:, 0] ** 2 + pw[:, 1] ** 2
    target = rho2 + h * h - a2 * a2  # |P_h|^2 for any neck pose with y_h = 0

    def crossing(alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t1, t2 = np.tan(alpha + e1), np.tan(alpha + e2)
        z = head.baseline / (t1 + t2)
        return z * t1 - half, z, t1

    def excess(alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x, z, t1 = crossing(alpha)
        sec1, sec2 = 1.0 + t1 * t1, 1.0 + np.tan(alpha + e2) ** 2
        dz = -z * (sec1 + sec2) / (t1 + np.tan(alpha + e2))
        dx = dz * t1 + z * sec1
        return target - (x * x + z * z), -2.0 * (x * dx + z * dz)

    lo = -(e1 + e2) / 2.0 + 1e-9
    hi = math.pi / 2 - max(e1, e2) - 1e-9
    start = np.full(pw.shape[0], 0.5 * (lo + hi))
    with np.errstate(invalid="ignore"):
        alpha, _ = solve_increasing(
            excess, np.full_like(start, lo), np.full_like(start, hi), start, 1e-16
        )
        qx, qz, _ = crossing(alpha)
        w = np.sqrt(rho2 - qx * qx)
    theta2 = np.arctan2(h, w) - np.arctan2(a2, qz)
    theta1 = np.arctan2(pw[:, 1], pw[:, 0]) - np.arctan2(w, qx)
    theta1 = (theta1 + math.pi) % (2.0 * math.pi) - math.pi
    valid = np.isfinite(alpha) & np.isfinite(w) & (w > 0.0) & (target > 0.0)
    nan = np.full_like(alpha, np.nan)
    if quantised:
        alpha = quantise(alpha, head.encoder_resolution)
    points_h = np.stack([qx, np.zeros_like(qx), qz], axis=-1)
    return NeckFixation(
        theta1=np.where(valid, theta1, nan),
        theta2=np.where(valid, theta2, nan),
        alpha=np.where(valid, alpha, nan),
        points_h=np.where(valid[:, None], points_h, np.nan),
        valid=valid,
    )
