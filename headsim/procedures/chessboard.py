"""The chessboard's inner corners with Model 2 and the squares they give (Sec. VI-A)."""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from headsim.active.chessboard import measure_chessboard
from headsim.active.events import PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge
from headsim.run.context import (
    PAPER,
    model2_config,
    record_measurement,
    servo_config,
    simulator,
)
from headsim.run.events import Hub
from headsim.run.outcomes import (
    ChessboardPaper,
    ChessboardResult,
    MeasurementRecord,
)
from headsim.run.table import format_table, mm
from headsim.scenario.registry import Procedure, register
from headsim.scenario.spec import CHESSBOARD_PATTERN, CHESSBOARD_SQUARE_M, Scenario
from headsim.sim import names


def _stats(values: np.ndarray) -> tuple[float, float]:
    """Mean and sample standard deviation (NaN where undefined)."""
    mean = float(values.mean()) if values.size else float("nan")
    std = float(values.std(ddof=1)) if values.size > 1 else float("nan")
    return mean, std


def run_chessboard(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], ChessboardResult]:
    """Every chosen inner corner with Model 2 (Sec. VI-A), and the squares they give."""
    scene = scenario.scene
    assert scene.chessboard is not None
    columns = CHESSBOARD_PATTERN[0]
    indices = (
        list(scene.corners)
        if scene.corners is not None
        else list(range(columns * CHESSBOARD_PATTERN[1]))
    )
    with simulator(hub, "chessboard", scenario) as sim:
        sim.set_body_pose(names.CHESSBOARD, np.array(scene.chessboard.position_world_m))
        body = sim.data.body(names.CHESSBOARD)
        rotation = body.xmat.reshape(3, 3)
        truth = {
            f"corner_{k % columns}_{k // columns}": body.xpos
            + rotation
            @ np.array(
                [(k % columns) * CHESSBOARD_SQUARE_M, (k // columns) * CHESSBOARD_SQUARE_M, 0.0]
            )
            for k in indices
        }
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        run = measure_chessboard(
            sim,
            EyeServo(sim, servo_config(scenario)),
            knowledge,
            model2_config(scenario),
            CHESSBOARD_PATTERN,
            CHESSBOARD_SQUARE_M,
            indices,
        )
        steps = hub.steps
    records = [
        record_measurement(hub, m, label, step)
        for m, step in zip(run.measurements, steps, strict=True)
    ]
    sides = np.concatenate([run.widths_m, run.heights_m])
    width, height, side = _stats(run.widths_m), _stats(run.heights_m), _stats(sides)
    experiment = ChessboardResult(
        pattern=list(CHESSBOARD_PATTERN),
        square_m=CHESSBOARD_SQUARE_M,
        corners=len(indices),
        corners_measured=run.measured,
        widths_m=run.widths_m,
        heights_m=run.heights_m,
        true_widths_m=run.true_widths_m,
        true_heights_m=run.true_heights_m,
        width_mean_m=width[0],
        width_std_m=width[1],
        height_mean_m=height[0],
        height_std_m=height[1],
        side_mean_m=side[0],
        side_std_m=side[1],
        paper=ChessboardPaper(
            side_mean_m=PAPER["chessboard_side_mean_m"],
            side_std_m=PAPER["chessboard_side_std_m"],
        ),
    )
    return records, experiment


def _chessboard_lines(e: ChessboardResult, paper: bool) -> list[str]:
    headers = ["", "n", "mean mm", "std mm", "truth mm"] + (
        ["paper mean", "paper std"] if paper else []
    )
    sides = (
        ("widths", e.widths_m, e.true_widths_m, e.width_mean_m, e.width_std_m),
        ("heights", e.heights_m, e.true_heights_m, e.height_mean_m, e.height_std_m),
        (
            "all sides",
            np.concatenate([e.widths_m, e.heights_m]),
            np.concatenate([e.true_widths_m, e.true_heights_m]),
            e.side_mean_m,
            e.side_std_m,
        ),
    )
    rows = []
    for label, values, true_values, mean_m, std_m in sides:
        truth = np.asarray(true_values)
        paper_cells = ["-", "-"]
        if label == "all sides":
            paper_cells = [mm(e.paper.side_mean_m, ".1f"), mm(e.paper.side_std_m, ".3f")]
        rows.append(
            [
                label,
                str(len(values)),
                mm(mean_m, ".3f"),
                mm(std_m, ".3f"),
                mm(float(np.mean(truth)) if len(truth) else None, ".3f"),
                *(paper_cells if paper else []),
            ]
        )
    title = (
        f"Chessboard squares (Tables III, IV): {e.corners_measured} of {e.corners} cross "
        f"points measured, squares {e.square_m * 1000:g} mm"
    )
    return [title, *format_table(headers, rows)]


CHESSBOARD = register(
    Procedure("chessboard", "chessboard", run_chessboard, fields=asdict, summary=_chessboard_lines)
)


__all__ = ["CHESSBOARD", "run_chessboard"]
