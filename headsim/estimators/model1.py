"""Model 1, the humanoid head with a neck (Sec. II-B, eqs. 2-3), vectorised.

The neck puts P in the plane of the optical axes and on the perpendicular
bisector of C1C2, the eyes verge on it with encoder reading alpha; then in H

    x_h = y_h = 0,  z_h = D / (2 tan(alpha + alpha_e))      (2)

and p_W = W_T_H p_H with the neck angles, eq. (3) (see ``PositionEstimate.to_world``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from headsim.estimators.errors import model1_covariance
from headsim.estimators.result import (
    Flag,
    PositionEstimate,
    Uncertainty,
    as_vector,
    check_angles,
    check_baseline,
)

__all__ = ["model1"]


def model1(
    alpha: ArrayLike,
    baseline: float,
    *,
    alpha_e: float | tuple[float, float] = 0.0,
    uncertainty: Uncertainty | None = None,
    los_offset_m: tuple[float, float] = (0.0, 0.0),
) -> PositionEstimate:
    """Positions (N, 3) in H of points fixated with the neck, eq. (2).

    alpha: (N,) eye encoder reading at fixation, rad.  baseline: D, m.
    alpha_e: the eyes' initial direction, rad.  A scalar is eq. (2) as written
    (symmetric eyes).  A pair (alpha_e1, alpha_e2) is exact for unequal
    offsets: one eye angle then centres P where the two lines of sight cross,
    off the Z_h axis, so z_h and x_h follow eqs. (4)-(5) with alpha1 = alpha2.
    uncertainty: baseline and encoder errors for the covariance of z_h, or None.
    los_offset_m: (s1, s2), m, each line of sight's offset from its yaw axis
    (see :func:`headsim.estimators.model2`): P is the crossing of the offset lines.
    Points with alpha + alpha_e <= 0 (lines of sight parallel or diverging) or
    >= pi/2 are flagged invalid.
    """
    a_enc = as_vector(alpha, "alpha")
    check_angles(a_enc, "alpha")
    d = check_baseline(baseline)
    pair = np.broadcast_to(np.asarray(alpha_e, dtype=float), (2,))
    check_angles(pair, "alpha_e")
    if not all(math.isfinite(float(o)) and abs(float(o)) < d / 2 for o in los_offset_m):
        raise ValueError(
            f"los_offset_m must be two offsets in metres, |s| < D/2, got {los_offset_m!r}"
        )
    a = a_enc + float(pair.mean())
    finite = np.isfinite(a)
    flags = np.zeros(a.shape, dtype=np.int64)
    flags[~finite] |= Flag.NONFINITE
    flags[finite & ~(a > 0.0)] |= Flag.NOT_CONVERGING
    flags[finite & ~(a < math.pi / 2)] |= Flag.BEHIND_CAMERA
    valid = flags == 0
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = np.tan(a_enc + pair[0]), np.tan(a_enc + pair[1])
        o1, o2 = (float(o) for o in los_offset_m)
        sec1, sec2 = np.sqrt(1.0 + t1 * t1), np.sqrt(1.0 + t2 * t2)
        depth = d - o1 * sec1 + o2 * sec2  # the offset lines' crossing (model2's docstring)
        z = np.where(valid, depth / (t1 + t2), np.nan)  # = D / (2 tan a) for equal offsets
        x = np.where(valid, z * t1 + o1 * sec1 - 0.5 * d, np.nan)  # 0 for equal offsets
    positions = np.stack([x, np.zeros_like(z), z], axis=-1)
    positions[~valid] = np.nan
    covariance = None
    if uncertainty is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            covariance = model1_covariance(a, d, uncertainty)
        covariance[~valid] = np.nan
    return PositionEstimate(positions, valid, flags, covariance)
