"""The chessboard of Sec. VI-A as a target: each inner corner read off the whole board,
and the board found in a camera's next image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from headsim.active.look import look_once
from headsim.active.measurement import Target
from headsim.head.servo_head import ServoHead
from headsim.sim import names
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

    def truth(sim: ServoHead) -> np.ndarray:
        body = sim.truth.data.body(names.CHESSBOARD)
        return body.xpos + body.xmat.reshape(3, 3) @ np.array([i * square_m, j * square_m, 0.0])

    return Target(f"corner_{i}_{j}", ChessboardCorner(index, pattern, square_m), truth)


#: The binning of the preview that places a board seen for the first time (stereo's
#: and the zoom's views): the scene's 30 mm squares, 28.6 px at 0.85 m at the paper's
#: focal length, stay >= 10 px at 2 x 2 to about 1.2 m (OpenCV found every board of 14 px
#: squares and none of 7 px); a board the preview misses is found in the full frame.
BOARD_PREVIEW_BINNING = 2


def look_for_board(sim: ServoHead, camera: int) -> np.ndarray | None:
    """The scene's board's inner corners (N, 2) px in ``camera``'s next image, in board
    order (as ``headsim.stereo.views.detect_chessboard`` gives them), or None: found in
    the window a binned preview places (:func:`look_once`), else in the full frame."""
    seen = look_once(sim, camera, _BOARD.detector, binning=BOARD_PREVIEW_BINNING)
    if not seen.found or seen.pattern_uv is None:
        return None
    return np.array(seen.pattern_uv, dtype=float)


_BOARD = chessboard_corner_target(0, CHESSBOARD_PATTERN, CHESSBOARD_SQUARE_M)

__all__ = [
    "BOARD_PREVIEW_BINNING",
    "ChessboardCorner",
    "board_extent",
    "chessboard_corner_target",
    "look_for_board",
]
