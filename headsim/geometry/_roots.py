"""Vectorised root finding for increasing scalar functions (private helper)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["solve_increasing"]

_EPS = float(np.finfo(float).eps)


def solve_increasing(
    f: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    lo: np.ndarray,
    hi: np.ndarray,
    x0: np.ndarray,
    xtol: float,
    max_iter: int = 200,
) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``f(x) = 0`` element-wise for an increasing ``f`` on ``[lo, hi]``.

    ``f`` returns ``(value, derivative)`` for an array of ``x``.  Newton steps that
    leave the bracket are replaced by bisection, so the iteration cannot diverge;
    it stops where a step is below ``xtol`` or a few ulps of ``x``.
    Returns ``(x, bracketed)``: ``bracketed`` is False where ``f(lo) > 0`` or
    ``f(hi) < 0`` (no root in the bracket; ``x`` is then NaN).  The caller checks
    the residual it cares about.
    """
    lo, hi = np.array(lo, float), np.array(hi, float)
    f_lo, _ = f(lo)
    f_hi, _ = f(hi)
    bracketed = (f_lo <= 0.0) & (f_hi >= 0.0)
    x = np.clip(np.asarray(x0, float), lo, hi)
    active = bracketed.copy()
    for _ in range(max_iter):
        if not active.any():
            break
        value, slope = f(x)
        above = value > 0.0
        hi = np.where(active & above, x, hi)
        lo = np.where(active & ~above, x, lo)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = x - value / slope
        inside = (slope > 0.0) & (newton > lo) & (newton < hi)
        step_to = np.where(value == 0.0, x, np.where(inside, newton, 0.5 * (lo + hi)))
        done = np.abs(step_to - x) <= xtol + 4.0 * _EPS * np.abs(x)
        x = np.where(active, step_to, x)
        active &= ~done
    return np.where(bracketed, x, np.nan), bracketed
