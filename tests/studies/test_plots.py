"""The orchestrators' figures (studies/plots.py): real PNGs of the stated size, a style per
method, the mean drawn only over repeated values, nothing for a field that is not numeric."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np

from headsim.studies.methods import METHODS
from headsim.studies.plots import STYLE, plot_budget, plot_metric

#: Matplotlib's C3 (tab:red), the mean's colour, as OpenCV reads it (B, G, R).
C3_BGR = np.array([40, 39, 214])


def _red_pixels(path: Path) -> int:
    image = cv2.imread(str(path)).astype(int)
    return int((np.abs(image - C3_BGR).max(axis=2) < 20).sum())


def test_every_method_has_its_own_colour_and_marker() -> None:
    assert set(STYLE) == set(METHODS)
    assert len({s["color"] for s in STYLE.values()}) == len(METHODS)
    assert len({s["marker"] for s in STYLE.values()}) == len(METHODS)


def test_a_metric_is_plotted_with_its_mean_over_repeated_values(tmp_path: Path) -> None:
    unique = [{"kx": 600.0 + 100 * i, "err": 0.1 * i} for i in range(4)]
    repeated = [*unique, {"kx": 600.0, "err": 0.3}, {"kx": 700.0, "err": 0.5}]
    one = plot_metric(unique, "kx", "err", tmp_path / "one.png", "title")
    two = plot_metric(repeated, "kx", "err", tmp_path / "two.png", "title")
    assert one == tmp_path / "one.png" and two == tmp_path / "two.png"
    assert cv2.imread(str(one)).shape == (400, 600, 3)
    assert _red_pixels(one) == 0 and _red_pixels(two) > 100
    # Not numeric, or fewer than two points: no plot, no file.
    names = [{"kx": "wide", "err": 0.1}, {"kx": "narrow", "err": 0.2}]
    assert plot_metric(names, "kx", "err", tmp_path / "names.png", "t") is None
    assert plot_metric(unique[:1], "kx", "err", tmp_path / "single.png", "t") is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one.png", "two.png"]


def test_the_budget_chart_grows_with_its_conditions_and_takes_a_nan(tmp_path: Path) -> None:
    rows = [
        {"condition": f" c{i} ", "rms_3d_pct": 0.1 * i, "rms_xz_pct": 0.05, "predicted_xz_pct": x}
        for i, x in enumerate([0.04, math.nan, 0.06, 0.07])
    ]
    path = plot_budget(rows, tmp_path / "budget.png")
    height, width, _ = cv2.imread(str(path)).shape
    assert (height, width) == (round(110 * (0.45 * 4 + 1.6)), 990)
    taller = plot_budget(rows * 2, tmp_path / "taller.png")
    assert cv2.imread(str(taller)).shape[0] == round(110 * (0.45 * 8 + 1.6))
