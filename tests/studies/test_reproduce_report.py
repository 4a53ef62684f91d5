"""``headsim reproduce``'s rows and report: verdicts against the paper, failures beside the rest."""

from __future__ import annotations

from pathlib import Path

from headsim.studies.reproduce_experiments import JobOutcome
from headsim.studies.reproduce_report import report_sections, report_text
from headsim.studies.reproduce_rows import chessboard_rows, initial_direction_rows, study_rows


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


CALIBRATION = {
    "head_hash": "ab" * 32,
    "block": {
        "alpha_e_rad": [0.05790, -0.02530],
        "alpha_e_std_rad": [2e-4, 2e-4],
        "fixated": 11,
        "targets": 12,
        "renders": 75,
    },
}


BOARD = {
    "results": {
        "experiment": {
            "side_mean_m": 0.03003,
            "side_std_m": 0.0004,
            "corners": 6,
            "corners_measured": 6,
            "widths_m": [0.0300],
            "heights_m": [0.0301],
        }
    }
}


def test_rows_compare_with_the_papers_figures() -> None:
    rows = initial_direction_rows(CALIBRATION, None)
    assert [r.verdict for r in rows] == ["reproduced", "reproduced"]
    far = {**CALIBRATION, "block": {**CALIBRATION["block"], "alpha_e_rad": [0.0600, -0.0254]}}
    assert initial_direction_rows(far, None)[0].verdict.startswith("differs by +2.2e-03")
    board = chessboard_rows(BOARD)
    assert board[0].ours == "30.030" and board[0].verdict.startswith("reproduced")
    worse = {"results": {"experiment": {**BOARD["results"]["experiment"], "side_mean_m": 0.0306}}}
    assert chessboard_rows(worse)[0].verdict == "not reproduced"
    study = {
        "figures": {
            "tables_v_vi": {"stereo_rms_mm": 0.6, "active_v_known_over_stereo": 1.3},
            "zoom_1_5_paper": {
                "stereo_after_over_before": 300.0,
                "active_fixed_point_after_over_before": 1.4,
            },
        }
    }
    verdicts = [r.verdict for r in study_rows(study)]
    assert verdicts == ["reference", "reproduced", "reproduced (stereo degrades)", "reproduced"]


def test_a_failed_experiment_is_reported_beside_the_others(tmp_path: Path) -> None:
    outcomes = {
        "chessboard": JobOutcome("chessboard", "ok", 12.0, BOARD),
        "tracking": JobOutcome("tracking", "error", 3.0, error="RuntimeError: GL context lost"),
    }
    text = report_text(_state(tmp_path, "failed"), outcomes, CALIBRATION, None)
    assert "**FAILED**: RuntimeError: GL context lost" in text
    assert "| square side, mean, mm (true 30) | 30.3 | 30.030 |" in text
    assert "hash `abababababab`" in text and "seed: 0" in text
    # Not yet run (an interrupted run): said so, the rest readable.
    interrupted = report_text(_state(tmp_path, "interrupted"), outcomes, CALIBRATION, None)
    assert "not run (interrupted)" in interrupted
    sections = {
        name: rows for name, _, rows, _ in report_sections(_state(tmp_path), outcomes, CALIBRATION)
    }
    assert sections["tracking"] is None and sections["chessboard"]
