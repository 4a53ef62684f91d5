"""The chessboard of Sec. VI-A: every chosen inner corner measured with Model 2,
and the squares' sides they give.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from headsim.active.events import FixationStarted, MeasurementDone
from headsim.active.eye_servo import EyeServo
from headsim.active.look import look_once
from headsim.active.measurement import (
    HeadKnowledge,
    Measurement,
    Target,
)
from headsim.active.model2 import Model2Config, measure_model2
from headsim.sim import names
from headsim.sim.events import EventSink
from headsim.sim.simulator import HeadSim
from headsim.stereo.views import CHESSBOARD_PATTERN, CHESSBOARD_SQUARE_M
from headsim.vision.chessboard import (
    ChessboardDetection,
    find_chessboard,
)
from headsim.vision.detection import Detection, DetectionStatus


def board_extent(board: ChessboardDetection, index: int) -> tuple[float, float, float, float]:
    """(left, top, right, bottom) px from corner ``index`` of what finding ``board`` needs:
    its inner corners and the outer squares (one square beyond them; the window adds
    its margin of the white border around).  Half a square of border more found every
    corner too, in windows 27 % larger (Dec 2026: 312 renders, none missed, either way)."""
    corners = board.corners
    assert corners is not None
    columns, rows = board.pattern
    grid = corners.reshape(rows, columns, 2)
    spacing = float(
        max(
            np.linalg.norm(np.diff(grid, axis=1), axis=-1).max(),
            np.linalg.norm(np.diff(grid, axis=0), axis=-1).max(),
        )
    )
    low, high = corners.min(axis=0) - corners[index], corners.max(axis=0) - corners[index]
    pad = 1.0 * spacing
    return (
        float(low[0] - pad),
        float(low[1] - pad),
        float(high[0] + pad),
        float(high[1] + pad),
    )


@dataclass(frozen=True, eq=False)
class ChessboardCorner:
    """The detector of inner corner ``index`` of a board of ``pattern`` inner corners: the
    whole board found (a :class:`~headsim.active.look.PatternFeature`).  Every corner of one
    board shares its windows (``window_key``), which hold the whole board."""

    index: int
    pattern: tuple[int, int]
    square_m: float

    @property
    def window_key(self) -> tuple[str, tuple[int, int], float]:
        return ("chessboard", self.pattern, self.square_m)

    def __call__(self, image: np.ndarray) -> Detection:
        board = find_chessboard(image, self.pattern)
        if not board.found:
            return Detection(board.status, None, 0.0)
        assert board.corners is not None  # found: the corners are there
        u, v = board.corners[self.index]
        return Detection(
            DetectionStatus.FOUND,
            (float(u), float(v)),
            1.0,
            board_extent(board, self.index),
            pattern_uv=tuple((float(a), float(b)) for a, b in board.corners),
            pattern_scale_px=board.spacing_px,
        )


def chessboard_corner_target(index: int, pattern: tuple[int, int], square_m: float) -> Target:
    """Inner corner ``index`` (row-major from the top-left) of the scene's chessboard.

    Found by detecting the whole board (:class:`ChessboardCorner`): a board cut by
    the image border loses its corners, it does not guess them.
    """
    columns, _ = pattern
    i, j = index % columns, index // columns

    def truth(sim: HeadSim) -> np.ndarray:
        body = sim.data.body(names.CHESSBOARD)
        return body.xpos + body.xmat.reshape(3, 3) @ np.array([i * square_m, j * square_m, 0.0])

    return Target(f"corner_{i}_{j}", ChessboardCorner(index, pattern, square_m), truth)


#: The binning of the preview that places a board seen for the first time (stereo's
#: and the zoom's views): the scene's 30 mm squares, 28.6 px at 0.85 m at the paper's
#: focal length, stay >= 10 px at 2 x 2 to about 1.2 m (OpenCV found every board of 14 px
#: squares and none of 7 px); a board the preview misses is found in the full frame.
BOARD_PREVIEW_BINNING = 2


def look_for_board(sim: HeadSim, camera: int) -> np.ndarray | None:
    """The scene's board's inner corners (N, 2) px in ``camera``'s next image, in board
    order (as ``headsim.stereo.views.detect_chessboard`` gives them), or None: found in
    the window a binned preview places (:func:`look_once`), else in the full frame."""
    seen = look_once(sim, camera, _BOARD.detector, binning=BOARD_PREVIEW_BINNING)
    if not seen.found or seen.pattern_uv is None:
        return None
    return np.array(seen.pattern_uv, dtype=float)


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
    sim: HeadSim,
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
    reported (None: the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    columns, rows = pattern
    indices = list(range(columns * rows)) if corners is None else list(corners)
    measured: dict[int, Measurement] = {}
    for k in indices:
        corner = chessboard_corner_target(k, pattern, square_m)
        sink.emit(FixationStarted(corner.name))
        measured[k] = measure_model2(sim, servo, corner, knowledge, config)
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


_BOARD = chessboard_corner_target(0, CHESSBOARD_PATTERN, CHESSBOARD_SQUARE_M)

__all__ = [
    "BOARD_PREVIEW_BINNING",
    "ChessboardCorner",
    "ChessboardRun",
    "board_extent",
    "chessboard_corner_target",
    "look_for_board",
    "measure_chessboard",
]
