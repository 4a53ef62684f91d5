"""Extended calibration (beyond the paper): each camera's vertical reference and kx/ky.

Eq. (7) needs, besides the servo's goal column u_i0, the row v_i0 of the
principal point and the pixel aspect ratio r_i = kx_i / ky_i.  From targets at
known positions the y of P in the camera's frame is known, so

    y_c (u - u_i0) = r (v - v_i0) x_c  =  r x_c v - (r v_i0) x_c

is linear in (r, r v_i0): ordinary least squares over the samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["VerticalCalibration", "calibrate_vertical_reference"]


@dataclass(frozen=True)
class VerticalCalibration:
    """Fitted vertical reference row v0 (px) and kx/ky, their standard errors, residuals (m)."""

    v0: float
    kx_over_ky: float
    v0_std: float
    kx_over_ky_std: float
    residuals_m: np.ndarray


def calibrate_vertical_reference(
    u_d: ArrayLike, v: ArrayLike, x_c: ArrayLike, y_c: ArrayLike
) -> VerticalCalibration:
    """Fit (v0, kx/ky) of one camera from n >= 3 samples.

    u_d: (n,) P's column offset u - u_i0 in the y image, px.  v: (n,) P's row
    there, px.  x_c: (n,) P's x in the camera's frame then, m (eq. 8 or 10).
    y_c: (n,) P's true y, m.  Samples need a spread of heights.
    """
    u_d, v, x_c, y_c = (np.asarray(a, dtype=float).ravel() for a in (u_d, v, x_c, y_c))
    n = u_d.size
    if not (v.size == x_c.size == y_c.size == n):
        raise ValueError("u_d, v, x_c, y_c must have one length")
    if n < 3:
        raise ValueError(f"the vertical calibration needs at least 3 samples, got {n}")
    if not all(np.isfinite(a).all() for a in (u_d, v, x_c, y_c)):
        raise ValueError("vertical calibration samples must be finite")
    design = np.column_stack([x_c * v, -x_c])
    rhs = y_c * u_d
    solution, *_ = np.linalg.lstsq(design, rhs, rcond=None)
    r, q = solution
    if not r > 0:
        raise ValueError(f"the fitted kx/ky ratio is not positive ({r}): samples are degenerate")
    residual = rhs - design @ solution
    dof = max(n - 2, 1)
    cov = np.linalg.pinv(design.T @ design) * float(residual @ residual) / dof
    v0 = q / r
    # Delta method for v0 = q / r.
    grad = np.array([-q / r**2, 1.0 / r])
    v0_std = float(np.sqrt(max(grad @ cov @ grad, 0.0)))
    y_model = r * (v - v0) * x_c / np.where(u_d == 0, np.nan, u_d)
    return VerticalCalibration(
        v0=float(v0),
        kx_over_ky=float(r),
        v0_std=v0_std,
        kx_over_ky_std=float(np.sqrt(max(cov[0, 0], 0.0))),
        residuals_m=y_model - y_c,
    )
