"""The chessboard's inner corners with Model 2 and the squares they give (Sec. VI-A)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from headsim.active.chessboard import chessboard_corner_target
from headsim.active.events import FixationStarted, MeasurementDone, PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.active.model2 import Model2Config, measure_model2
from headsim.codec import declared, doc
from headsim.head.servo_head import ServoHead
from headsim.procedures.contract import Procedure, register
from headsim.runs.context import (
    PAPER,
    head,
    model2_config,
    record_measurement,
    servo_config,
)
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.table import format_table, mm
from headsim.scenario.scene import (
    default_position,
    position_of,
    read_position,
    tuple3,
)
from headsim.scenario.schema import interpolate_option, near_midline_options
from headsim.scenario.spec import (
    CHESSBOARD_PATTERN,
    CHESSBOARD_SQUARE_M,
    CalibrationSpec,
    Placement,
    Scenario,
    SceneSpec,
    corner_count,
)
from headsim.scenario.tables import Context, Table, describe_value
from headsim.sim import names
from headsim.sim.declared import Array, Section
from headsim.sim.events import EventSink
from headsim.sim.settings import HeadSettings


@declared
class ChessboardPaper:
    """Table III/IV's square side, mean and std, m."""

    side_mean_m: float = doc("the paper's mean side, m (0.0303)")
    side_std_m: float = doc("the paper's std, m (0.000677)")


@declared
class ChessboardResult:
    """The chessboard's inner corners with Model 2 and the squares they give (Sec. VI-A), m."""

    pattern: list[int] = doc("inner corners (columns, rows)")
    square_m: float = doc("the squares' side, m")
    corners: int = doc("inner corners")
    corners_measured: int = doc("corners measured")
    widths_m: np.ndarray = doc("each square's measured width, m")
    heights_m: np.ndarray = doc("each square's measured height, m")
    true_widths_m: np.ndarray = doc("their true widths, m")
    true_heights_m: np.ndarray = doc("their true heights, m")
    width_mean_m: float = doc("mean width, m")
    width_std_m: float = doc("its std, m")
    height_mean_m: float = doc("mean height, m")
    height_std_m: float = doc("its std, m")
    side_mean_m: float = doc("mean of all sides, m")
    side_std_m: float = doc("its std, m")
    paper: ChessboardPaper = doc("Tables III/IV's square side")

    def summary_lines(self, paper: bool) -> list[str]:
        """The squares' widths, heights and all sides beside the truth (and the paper's)."""
        headers = ["", "n", "mean mm", "std mm", "truth mm"] + (
            ["paper mean", "paper std"] if paper else []
        )
        sides = (
            ("widths", self.widths_m, self.true_widths_m, self.width_mean_m, self.width_std_m),
            ("heights", self.heights_m, self.true_heights_m, self.height_mean_m, self.height_std_m),
            (
                "all sides",
                np.concatenate([self.widths_m, self.heights_m]),
                np.concatenate([self.true_widths_m, self.true_heights_m]),
                self.side_mean_m,
                self.side_std_m,
            ),
        )
        rows = []
        for label, values, true_values, mean_m, std_m in sides:
            truth = np.asarray(true_values)
            paper_cells = ["-", "-"]
            if label == "all sides":
                paper_cells = [mm(self.paper.side_mean_m, ".1f"), mm(self.paper.side_std_m, ".3f")]
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
            f"Chessboard squares (Tables III, IV): {self.corners_measured} of {self.corners} cross "
            f"points measured, squares {self.square_m * 1000:g} mm"
        )
        return [title, *format_table(headers, rows)]


@dataclass(frozen=True)
class ChessboardRun:
    """Every cross point measured with Model 2, and the squares' sides they give, m.

    ``widths_m``/``heights_m``: distances between horizontally/vertically
    adjacent measured corners (estimate), with the truth beside them.
    """

    measurements: tuple[Measurement, ...]
    square_m: float
    widths_m: np.ndarray
    heights_m: np.ndarray
    true_widths_m: np.ndarray
    true_heights_m: np.ndarray

    @property
    def measured(self) -> int:
        return sum(m.ok for m in self.measurements)


def measure_chessboard(
    head: ServoHead,
    servo: EyeServo,
    knowledge: HeadKnowledge | None = None,
    config: Model2Config | None = None,
    pattern: tuple[int, int] = (8, 6),
    square_m: float = 0.030,
    corners: Sequence[int] | None = None,
    sink: EventSink | None = None,
) -> ChessboardRun:
    """Measure the chessboard's cross points (all, or ``corners``) and its squares' sides.

    ``sink``: where each corner's fixation ("corner_i_j") and measurement is
    reported (None: the head's sink).
    """
    sink = head.sink if sink is None else sink
    columns, rows = pattern
    indices = list(range(columns * rows)) if corners is None else list(corners)
    measured: dict[int, Measurement] = {}
    for k in indices:
        corner = chessboard_corner_target(k, pattern, square_m)
        sink.emit(FixationStarted(corner.name))
        measured[k] = measure_model2(head, servo, corner, knowledge, config)
        sink.emit(MeasurementDone(measured[k]))
    widths: list[float] = []
    heights: list[float] = []
    true_widths: list[float] = []
    true_heights: list[float] = []
    for k, m in measured.items():
        for neighbour, out, out_true in (
            (k + 1, widths, true_widths),
            (k + columns, heights, true_heights),
        ):
            if neighbour == k + 1 and (k + 1) % columns == 0:
                continue
            other = measured.get(neighbour)
            if other is None or not (m.ok and other.ok):
                continue
            out.append(float(np.linalg.norm(other.estimate_head_m - m.estimate_head_m)))
            out_true.append(float(np.linalg.norm(other.truth_head_m - m.truth_head_m)))
    return ChessboardRun(
        measurements=tuple(measured.values()),
        square_m=square_m,
        widths_m=np.array(widths),
        heights_m=np.array(heights),
        true_widths_m=np.array(true_widths),
        true_heights_m=np.array(true_heights),
    )


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
    with head(hub, "chessboard", scenario) as sim:
        sim.truth.set_body_pose(names.CHESSBOARD, np.array(scene.chessboard.position_world_m))
        body = sim.truth.data.body(names.CHESSBOARD)
        rotation = body.xmat.reshape(3, 3)
        truth = {
            f"corner_{k % columns}_{k // columns}": body.xpos
            + rotation
            @ np.array(
                [(k % columns) * CHESSBOARD_SQUARE_M, (k // columns) * CHESSBOARD_SQUARE_M, 0.0]
            )
            for k in indices
        }
        hub.emit(PhaseStarted("measurement", sim.truth, knowledge, truth))
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


def read_chessboard(table: Table, ctx: Context, settings: HeadSettings, seed: int) -> SceneSpec:
    """``[scene.chessboard]``: where the board's top-left inner corner is; which corners."""
    board = table.section(BOARD) or Table({}, BOARD.path, ctx)
    position = read_position(board, settings, default_position("chessboard", names.CHESSBOARD))
    count = corner_count()
    corners_value = board.data.get(_CORNERS.name, "all")
    board.has(_CORNERS.name)
    allowed = f'"all" or an array of corner indices 0..{count - 1} (row-major from the top-left)'
    if corners_value == "all":
        corners = None
    elif (
        isinstance(corners_value, list)
        and corners_value
        and all(isinstance(c, int) and not isinstance(c, bool) for c in corners_value)
    ):
        if not all(0 <= c < count for c in corners_value) or len(set(corners_value)) != len(
            corners_value
        ):
            raise board.fail(
                "corners", f"{corners_value} has an index out of range or twice", allowed
            )
        corners = tuple(corners_value)
    else:
        raise board.fail(
            "corners", f'must be "all" or indices, got {describe_value(corners_value)}', allowed
        )
    board.done()
    placement = Placement(names.CHESSBOARD, names.CHESSBOARD, tuple3(position), board.path)
    return SceneSpec(scene="chessboard", chessboard=placement, corners=corners)


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: ``interpolate``, and the near-midline remedy's ``midline_px``, ``remedy_px``."""
    return {**interpolate_option(table), **near_midline_options(table)}


def _fixations(scenario: Scenario) -> int:
    return len(scenario.scene.corners or range(corner_count()))


#: The scenario table only it reads.
_CORNERS = Array("corners", '"all" or an array of corner indices (row-major from the top-left)', 'Which inner corners are measured: `"all"` or an array of corner indices, row-major from the top-left.', default=("all",))  # fmt: skip
BOARD = Section("scene.chessboard", "The chessboard (procedure `chessboard`); it faces the head.", (_CORNERS, *position_of("Top-left inner corner")))  # fmt: skip


CHESSBOARD = register(
    Procedure(
        "chessboard",
        "chessboard",
        run_chessboard,
        ChessboardResult,
        summary=ChessboardResult.summary_lines,
        options=read_options,
        read_scene=read_chessboard,
        fixations=_fixations,
        keys=(BOARD,),
        rank=50,
    )
)


__all__ = [
    "CHESSBOARD",
    "ChessboardPaper",
    "ChessboardResult",
    "ChessboardRun",
    "measure_chessboard",
    "run_chessboard",
]
