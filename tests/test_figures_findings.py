"""The findings page's predictions (tools/figures_findings.py) against the exact forward
model, and the figures over seeds (tools/figures_common.py): pure math, no rendering."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

import figures_common as common
import figures_findings as findings

from headsim.sim.settings import HeadSettings, paper_head
from headsim.studies.targets import table_targets


def _distortion_free(
    cy: tuple[float, float], cx: tuple[float | None, float | None]
) -> HeadSettings:
    """The paper's head without radial distortion, its principal points moved."""
    head = paper_head()
    cams = tuple(
        replace(c, k1=0.0, k2=0.0, cx=x, cy=y) for c, x, y in zip(head.cameras, cx, cy, strict=True)
    )
    return replace(head, cameras=cams)


def test_eq9_first_order_y_error_matches_the_exact_forward_model() -> None:
    # Rows 30 px below and 10 px above the centre: the terms do not cancel.
    settings = _distortion_free((269.5, 229.5), (None, None))
    term1, term2, mean = findings.predicted_centre_y_pct(settings)
    assert term1 > 0 > term2 and mean == pytest.approx(0.5 * (term1 + term2))
    forward = findings.predicted_forward(settings, table_targets())
    # First order in the ray's angle: the exact y error stays within 10 % of it.
    assert np.all(np.abs(forward["centre_y_pct"] - mean) < 0.1 * abs(mean))
    # With the principal rows at the centre the image centre costs y nothing.
    centred = findings.predicted_forward(
        _distortion_free((239.5, 239.5), (None, None)), table_targets()
    )
    assert np.max(np.abs(centred["centre_y_pct"])) < 1e-9


def test_a_kept_calibration_survives_the_zoom_only_with_the_goal_column_on_the_principal_point() -> (
    None
):
    targets = table_targets()
    on_axis = findings.predicted_forward(_distortion_free((239.5, 239.5), (None, None)), targets)
    assert max(abs(s) for s in on_axis["direction_shift_rad"]) < 1e-12
    assert np.max(on_axis["zoom_xz_pct"]) < 1e-6
    off = findings.predicted_forward(_distortion_free((239.5, 239.5), (303.5, 345.5)), targets)
    shift1, shift2 = off["direction_shift_rad"]
    # The goal column's ray turns by atan(du / kx) - atan(du / (1.5 kx)).
    cam1 = paper_head().cameras[0]
    expected = np.arctan(16.0 / (1.5 * cam1.kx)) - np.arctan(16.0 / cam1.kx)
    assert abs(shift1) == pytest.approx(abs(expected), rel=1e-6) and shift2 != 0.0
    assert np.min(off["zoom_xz_pct"]) > 0.1


def test_figures_over_seeds_give_the_median_and_the_range() -> None:
    assert common.median([3.0, 1.0, 2.0]) == 2.0 and common.median([4.0, 1.0, 2.0, 3.0]) == 2.5
    assert common.spread_pct([0.129, 0.252, 0.040, None]) == "0.129 % (0.040-0.252)"
    assert common.spread_pct([None]) == "-"
    assert common.seeds_label((0, 1, 2, 3, 4)) == "seeds 0-4"
    assert common.seeds_label((0, 2)) == "seeds 0, 2"


def test_the_heads_table_over_seeds_gives_each_cell_as_median_range_and_targets() -> None:
    heads = common.benchmark("heads")

    def row(rms: float, near: float | None, count: int) -> dict:
        return {
            "head": "paper",
            "procedure": "model2",
            "count": count,
            "ok": count,
            "refused": {"occluded": 1},
            "rms_pct": rms,
            "0-0.6 m": (near, 0 if near is None else 2),
            "0.6-1 m": (rms, count - 2),
            ">= 1 m": (None, 0),
            "renders_per_point": 10.0,
            "failures": [],
        }

    text = heads.seeds_text(
        [[row(0.2, 0.1, 5)], [row(0.4, None, 4)], [row(0.3, 0.3, 6)]], [0, 1, 2]
    )
    line = text.splitlines()[2]
    assert "median over seeds 0-2" in text.splitlines()[0]
    assert line.split()[2:4] == ["15", "3"]  # targets and refusals over the seeds
    assert "0.300 (0.200-0.400) [15/15]" in line  # all: median, range, measured/targets
    assert "0.200 (0.100-0.300) [4]" in line  # a band one seed lacks: two seeds' values
    assert line.split()[-3:] == ["-", "[0]", "10.0"]  # a band no seed has; renders per point
