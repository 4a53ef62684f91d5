"""Generators shared by the estimator tests."""

from __future__ import annotations

import numpy as np


def random_points(
    rng: np.random.Generator,
    n: int,
    r_range: tuple[float, float] = (0.2, 3.0),
    azimuth: float = 0.45,
    elevation: float = 0.3,
) -> np.ndarray:
    """n points (n, 3) in H at range r_range, m, within +-azimuth / +-elevation, rad."""
    r = rng.uniform(*r_range, n)
    az = rng.uniform(-azimuth, azimuth, n)
    el = rng.uniform(-elevation, elevation, n)
    return np.stack([r * np.cos(el) * np.sin(az), r * np.sin(el), r * np.cos(el) * np.cos(az)], -1)


def remedy_gammas(
    alpha1: np.ndarray, alpha2: np.ndarray, kx: float, min_ud: float, turn: float = 0.15
) -> tuple[np.ndarray, np.ndarray]:
    """Eye angles for the y images: the paper's (alpha2, alpha1), or, where those put P within
    ``min_ud`` px of the target column (near the Z_h axis), the generalised remedy: turn the eyes
    by ``turn`` rad away from the fixation so that |u_d| ~ kx tan(turn)."""
    near = np.abs(kx * np.tan(alpha1 - alpha2)) < min_ud
    return np.where(near, alpha1 - turn, alpha2), np.where(near, alpha2 + turn, alpha1)
