"""``headsim reproduce``'s report: failures beside the rest, interrupted runs readable."""

from __future__ import annotations

from pathlib import Path

from headsim.studies.catalogue import JobOutcome
from headsim.studies.reproduce_report import report_sections, report_text

from .helpers import BOARD, CALIBRATION


def _state(tmp_path: Path, status: str = "ok") -> dict:
    return {
        "status": status,
        "out": tmp_path,
        "fast": True,
        "workers": 2,
        "seed": 0,
        "sweeps": [],
        "render_s": 0.02,
        "wall_s": 30.0,
        "wall_over_render": 1500.0,
    }


def test_a_failed_experiment_is_reported_beside_the_others(tmp_path: Path) -> None:
    outcomes = {
        "chessboard": JobOutcome("chessboard", "ok", 12.0, BOARD),
        "tracking": JobOutcome("tracking", "error", 3.0, error="RuntimeError: GL context lost"),
    }
    text = report_text(_state(tmp_path, "failed"), outcomes, CALIBRATION, None)
    assert "**FAILED**: RuntimeError: GL context lost" in text
    assert (
        "| square side, mean, mm (true 30), paper preset (ideal mechanics) | 30.3 | 30.030 |"
        in (text)
    )
    # The first line counts the rows: 2 directions, the board's 5 (its realistic preset not
    # run: 2 rows without a figure, not reproduced) and the failed tracking (1).
    assert text.splitlines()[0] == (
        "# headsim reproduce: 5 of 8 rows reproduced, 3 not reproduced or failed, "
        "0 without a paper figure to compare"
    )
    assert "(not run)." in text
    assert "hash `abababababab`" in text and "seed: 0" in text
    # Not yet run (an interrupted run): said so, the rest readable.
    interrupted = report_text(_state(tmp_path, "interrupted"), outcomes, CALIBRATION, None)
    assert "not run (interrupted)" in interrupted
    sections = {
        name: rows for name, _, rows, _ in report_sections(_state(tmp_path), outcomes, CALIBRATION)
    }
    assert sections["tracking"] is None and sections["chessboard"]
