"""The chessboard's corners with Model 2 and its squares (Sec. VI-A)."""

from __future__ import annotations

from collections.abc import Callable

from headsim.procedures.chessboard import ChessboardResult
from headsim.runs.result import RunResult


def test_the_squares_measure_30_mm(fast_run: Callable[[str], RunResult]) -> None:
    result = fast_run("chessboard")
    assert result.ok, result.failures
    e = result.experiment
    assert isinstance(e, ChessboardResult)
    assert e.corners_measured == e.corners == len(result.records)
    assert abs(e.side_mean_m - 0.030) < 5e-4
    assert len(e.widths_m) == len(e.true_widths_m) and len(e.heights_m) == len(e.true_heights_m)
    assert (e.paper.side_mean_m, e.paper.side_std_m) == (0.0303, 0.000677)
