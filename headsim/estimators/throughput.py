"""Throughput of Model 2 against bare numpy references on the same arrays.

Used by ``benchmarks/estimators_throughput.py`` and ``headsim bench``; the
ratios to the references survive a change of machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from headsim.estimators import Uncertainty, model2
from headsim.geometry.synthetic import StereoHead, observe
from headsim.paper import BASELINE_M, INITIAL_DIRECTIONS_RAD

D = BASELINE_M
CENTRE = (319.5, 239.5)


def _best_time(fn: Callable[[], object], repeats: int) -> float:
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def _eq4_5(a1: np.ndarray, a2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t1 = np.tan(a1)
    z = D / (t1 + np.tan(a2))
    return z * t1 - D / 2, z


def _eq4_11(a1, a2, uv1, uv2) -> np.ndarray:
    x, z = _eq4_5(a1, a2)
    s = np.sin(a1 - a2) * z
    y1 = (uv1[:, 1] - CENTRE[1]) / (uv1[:, 0] - CENTRE[0]) * s / np.cos(a1)
    y2 = (uv2[:, 1] - CENTRE[1]) / (uv2[:, 0] - CENTRE[0]) * s / np.cos(a2)
    return np.stack([x, 0.5 * (y1 + y2), z], axis=-1)


def run(n_points: int, repeats: int, seed: int = 0) -> dict[str, float]:
    """Time the estimators on ``n_points`` synthetic points; figures in points per second."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.2, 3.0, n_points)
    az, el = rng.uniform(-0.4, 0.4, n_points), rng.uniform(-0.3, 0.3, n_points)
    points = np.stack(
        [r * np.cos(el) * np.sin(az), r * np.sin(el), r * np.cos(el) * np.cos(az)], -1
    )
    head = StereoHead(D, alpha_e1=INITIAL_DIRECTIONS_RAD[0], alpha_e2=INITIAL_DIRECTIONS_RAD[1])
    obs = observe(head, points)
    a1, a2, uv1, uv2 = obs.alpha1, obs.alpha2, obs.uv1, obs.uv2
    e = head.effective_initial_directions()

    def estimate(uncertainty=None):
        return model2(
            a1, a2, uv1, uv2, D, uv10=CENTRE, uv20=CENTRE, alpha_e=e, uncertainty=uncertainty
        )

    est = estimate()
    error = np.nanmax(np.abs(est.positions - points))
    unc = Uncertainty(baseline=0.5e-3, encoder=head.encoder_resolution, pixel=0.3)
    times = {
        "model2": _best_time(estimate, repeats),
        "model2_with_covariance": _best_time(lambda: estimate(unc), max(1, repeats // 3)),
        "numpy_eq4_5": _best_time(lambda: _eq4_5(a1 + e[0], a2 + e[1]), repeats),
        "numpy_eq4_11": _best_time(lambda: _eq4_11(a1 + e[0], a2 + e[1], uv1, uv2), repeats),
    }
    figures = {f"{k}_points_per_s": n_points / t for k, t in times.items()}
    figures["model2_over_numpy_eq4_5"] = times["numpy_eq4_5"] / times["model2"]
    figures["model2_over_numpy_eq4_11"] = times["numpy_eq4_11"] / times["model2"]
    figures["n_points"] = float(n_points)
    figures["n_valid"] = float(est.valid.sum())
    figures["max_abs_error_m"] = float(error)
    return figures
