"""What ``headsim reproduce`` runs: its experiments and jobs, the paper's figures it
compares with, how much each job costs (render-times), and each experiment's outcome."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from headsim.errors import BadInput

#: The scenarios run with the one calibration, and what each reproduces.
SCENARIO_JOBS = {
    "initial_directions": ("calibration", "Sec. V, Fig. 8: initial directions"),
    "chessboard": ("chessboard", "Sec. VI-A, Tables III-IV, Fig. 10: chessboard"),
    "relative_positioning": (
        "relative_positioning",
        "Sec. VI-C, Table VII, Fig. 12: relative positioning",
    ),
    "tracking": ("tracking", "Tracking with the neck (Model 1), beyond the paper"),
}
STUDY_JOB = "tables_v_vi"
#: What the Tables V/VI experiment measures here, and what it leaves to the study.
TABLES_SCOPE = (
    "Measured on this head with `head.json` (the image-centre active methods), one Zhang "
    "calibration (stereo) and one zoom fixed-point calibration (the fixed-point methods, "
    "beyond the paper, fewer ball positions than head.json): the six target positions, as calibrated and with the focal length "
    "x1.5. The three image-centre methods servo once and are computed from the same images. "
    "Smaller than `headsim study --experiment compare`, which also measures a "
    "second head with centred principal points and the 0.7x zoom, principal-point and k1 "
    "changes (beyond the paper's tables)."
)
#: Ball positions of the fixed-point methods' Sec. V calibration (beyond the paper), at
#: most: half of head.json's 60.  Their rows are the zoom's after/before ratios, which
#: the calibration's precision hardly moves (seed 0: 0.82 -> 0.85 and 1.51 -> 1.65
#: with 60 -> 30), and it halves the run's third-longest job (524 -> 248 renders).
FIXED_POINT_TARGETS = 30
#: The scenario whose head (and calibration) every experiment uses.
TABLES_HEAD = "calibration"
#: The job that measures the same board on the realistic preset (real tolerances), with the
#: chessboard scenario's own calibration: beside the paper preset, whose mechanics are ideal.
REALISTIC_BOARD_JOB = "chessboard_realistic"


class ReproduceError(BadInput, ValueError):
    """Bad input for ``headsim reproduce`` (exit 2)."""


@dataclass
class JobOutcome:
    """What one experiment returned: ``status`` "ok", "failed" (ran, a check failed) or "error"."""

    name: str
    status: str
    wall_s: float
    data: dict[str, Any] = field(default_factory=dict)
    error: str = ""


#: What each job costs, in 640x480 render-times at full size (its CPU time over the
#: run's render, medians of 3 runs of ``headsim reproduce --workers 2`` on this
#: machine, Dec 2026): the scheduler starts the ready job with the longest path to the
#: end first.  Sweeps are the longest.
COSTS = {
    "calibration": 185.0,
    "zhang": 120.0,
    "fixed_point": 130.0,
    "initial_directions": 12.0,
    "chessboard": 140.0,
    # Its CPU time 1.8x the chessboard job's (one run, Dec 2026), scaled from that job's cost.
    REALISTIC_BOARD_JOB: 250.0,
    "relative_positioning": 45.0,
    "tracking": 50.0,
    STUDY_JOB: 80.0,
}
SWEEP_COST = 1000.0
