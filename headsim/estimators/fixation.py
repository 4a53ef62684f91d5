"""One-step fixation with independent eyes: both eyes fixate P at once, each read from
its own encoder, with P in the plane of the optical axes (docs/equations.md, "Other
heads": eqs. (4), (5) with both angles read at the same instant)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from headsim.estimators.result import (
    Flag,
    PositionEstimate,
    Uncertainty,
    as_vector,
    check_angles,
    check_baseline,
)
from headsim.geometry.heads import fixation_point_head


def fixation(
    alpha1: ArrayLike,
    alpha2: ArrayLike,
    baseline: float,
    *,
    alpha_e: tuple[float, float] = (0.0, 0.0),
    uncertainty: Uncertainty | None = None,
    los_offset_m: tuple[float, float] = (0.0, 0.0),
) -> PositionEstimate:
    """Positions (N, 3) in H of points both eyes fixate at once.

    alpha1, alpha2: (N,) each eye's encoder reading, rad, positive inward.  baseline:
    D, m.  alpha_e: the initial directions, rad.  los_offset_m: each line of sight's
    offset from its pan axis, m.  The covariance takes D and each encoder as
    independent (``uncertainty``).  Points whose lines of sight do not meet in front
    are flagged invalid.
    """
    a1_enc, a2_enc = as_vector(alpha1, "alpha1"), as_vector(alpha2, "alpha2")
    check_angles(a1_enc, "alpha1")
    check_angles(a2_enc, "alpha2")
    d = check_baseline(baseline)
    a1, a2 = a1_enc + alpha_e[0], a2_enc + alpha_e[1]
    finite = np.isfinite(a1) & np.isfinite(a2)
    flags = np.zeros(a1.shape, dtype=np.int64)
    flags[~finite] |= Flag.NONFINITE
    with np.errstate(invalid="ignore"):
        behind = finite & ~((np.abs(a1) < math.pi / 2) & (np.abs(a2) < math.pi / 2))
        flags[behind] |= Flag.BEHIND_CAMERA
        flags[finite & ~behind & ~(np.tan(a1) + np.tan(a2) > 0.0)] |= Flag.NOT_CONVERGING
    valid = flags == 0
    positions = np.full((*a1.shape, 3), np.nan)
    if valid.any():
        positions[valid] = fixation_point_head(
            a1_enc[valid], a2_enc[valid], d, alpha_e, los_offset_m
        )
    covariance = None
    if uncertainty is not None:
        covariance = np.full((*a1.shape, 3, 3), np.nan)
        t1, t2 = np.tan(a1[valid]), np.tan(a2[valid])
        z = positions[valid, 2]
        s = t1 + t2
        # d z / d(D, a1, a2) and d x / d(...) of z = D / (t1 + t2), x = z t1 - D/2.
        dz = np.stack([z / d, -z * (1 + t1**2) / s, -z * (1 + t2**2) / s], axis=-1)
        dx = dz * t1[:, None] + np.stack(
            [np.full_like(z, -0.5), z * (1 + t1**2), np.zeros_like(z)], axis=-1
        )
        sigma = np.array([uncertainty.baseline, uncertainty.encoder, uncertainty.encoder])
        jac = np.zeros((z.shape[0], 3, 3))
        jac[:, 0], jac[:, 2] = dx * sigma, dz * sigma
        covariance[valid] = jac @ np.swapaxes(jac, 1, 2)
    return PositionEstimate(positions, valid, flags, covariance)


__all__ = ["fixation"]
