"""Throughput figures (estimators/throughput.py): complete, consistent and exact on a small run."""

from __future__ import annotations

import pytest

from headsim.estimators.throughput import run


def test_a_small_run_reports_every_figure_and_model2_is_exact() -> None:
    figures = run(n_points=2000, repeats=2, seed=1)
    assert figures["n_points"] == 2000.0
    # Noiseless synthetic points: all but the few on the image's centre column are valid.
    assert 0.99 * 2000 < figures["n_valid"] <= 2000
    assert figures["max_abs_error_m"] < 1e-9
    for name in ("model2", "model2_with_covariance", "numpy_eq4_5", "numpy_eq4_11"):
        assert figures[f"{name}_points_per_s"] > 0.0
    # The ratios are the reference's time over Model 2's: points per second, inverted.
    for reference in ("numpy_eq4_5", "numpy_eq4_11"):
        ratio = figures[f"{reference}_points_per_s"] ** -1 / figures["model2_points_per_s"] ** -1
        assert figures[f"model2_over_{reference}"] == pytest.approx(ratio, rel=1e-12)
