"""Chessboards (:func:`find_chessboard`): inner corners, pixels.

OpenCV finds the inner corners; they are refined with
:func:`cv2.cornerSubPix` on a Gaussian-blurred image (the blur makes the
gradient profile symmetric, removing the ~0.06 px bias the raw 1-px edge
ramp gives) and put into a fixed order (see :class:`ChessboardDetection`).
An incomplete board is CUT when X-junctions reach the image border, else
LOST: a board partly hidden inside the image is not told from one OpenCV
cannot find.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from headsim.vision.detection import DetectionStatus, to_grey
from headsim.vision.junctions import inside, junction_peaks, junction_response, refine_corners


@dataclass(frozen=True, eq=False)
class ChessboardDetection:
    """Inner corners of a chessboard: status and, if FOUND, ``corners`` (N, 2) px.

    ``pattern`` is (columns, rows) of inner corners, OpenCV's ``patternSize``.
    Corners are in row-major order with the first one top-left in the image
    and rows running left to right, rows ordered top to bottom: corner k is
    column ``k % columns``, row ``k // columns`` (:attr:`indices`).  For the
    scene's board facing the camera roughly upright (roll within +-45 deg),
    that is the board's inner corner (i, j) = (column, row), at
    (0.03 i, 0.03 j, 0) m in the board body frame.
    """

    status: DetectionStatus
    corners: np.ndarray | None
    pattern: tuple[int, int]
    #: The spacing of the corners OpenCV found, px: what the refinement is sized by.
    spacing_px: float = 0.0

    @property
    def found(self) -> bool:
        return self.status is DetectionStatus.FOUND

    @property
    def indices(self) -> np.ndarray:
        """Board indices (i, j) of each corner, (N, 2) int: column, row."""
        columns, rows = self.pattern
        j, i = np.divmod(np.arange(columns * rows), columns)
        return np.column_stack([i, j])


def orient_grid(corners: np.ndarray, pattern: tuple[int, int]) -> np.ndarray:
    """Reorder row-major grid corners (N, 2) to start top-left, rows left to right.

    OpenCV may return a grid from any of its four outer corners (and, for a
    square pattern, transposed).  Rows are made to run towards +u and follow
    each other towards +v.
    """
    columns, rows = pattern
    grid = np.asarray(corners, dtype=np.float64).reshape(rows, columns, 2)
    along_row = (grid[:, -1] - grid[:, 0]).mean(axis=0)
    if columns == rows and abs(along_row[1]) > abs(along_row[0]):
        grid = grid.transpose(1, 0, 2)
    if (grid[:, -1, 0] - grid[:, 0, 0]).mean() < 0:
        grid = grid[:, ::-1]
    if (grid[-1, :, 1] - grid[0, :, 1]).mean() < 0:
        grid = grid[::-1]
    return grid.reshape(-1, 2)


def _grid_spacing_px(grid_uv: np.ndarray, pattern: tuple[int, int]) -> float:
    """Smallest median distance between neighbouring corners along rows or columns, px."""
    columns, rows = pattern
    grid = grid_uv.reshape(rows, columns, 2)
    along_rows = np.linalg.norm(np.diff(grid, axis=1), axis=-1)
    along_columns = np.linalg.norm(np.diff(grid, axis=0), axis=-1)
    return float(min(np.median(along_rows), np.median(along_columns)))


def find_chessboard(
    image: np.ndarray,
    pattern: tuple[int, int] = (8, 6),
    *,
    min_contrast: float = 40.0,
) -> ChessboardDetection:
    """Sub-pixel inner corners of a chessboard with ``pattern`` (columns, rows).

    :func:`cv2.findChessboardCorners` finds them; each is refined with
    cornerSubPix on the image blurred in proportion to the square size
    (window about a third of a square) and ordered by :func:`orient_grid`.
    Status: FOUND with all corners; CUT when a corner lies so close to the
    border that its refinement window runs off the image, or when the
    pattern is not found but X-junctions of at least ``min_contrast`` grey
    levels lie within about one square of the image border (the board runs
    off the image); LOST otherwise (no board, or one too hidden or oblique
    for OpenCV).
    """
    columns, rows = (int(n) for n in pattern)
    if columns < 2 or rows < 2:
        raise ValueError(f"pattern must be at least (2, 2) inner corners, got {pattern}")
    grey = to_grey(image)
    # FAST_CHECK: an image without a board is rejected in ~2 ms instead of ~15.
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_FAST_CHECK
    ok, coarse = cv2.findChessboardCorners(grey, (columns, rows), flags=flags)
    if not ok or coarse is None:
        status = (
            DetectionStatus.CUT
            if _junctions_at_border(grey, min_contrast)
            else DetectionStatus.LOST
        )
        return ChessboardDetection(status, None, (columns, rows))
    coarse_uv = orient_grid(coarse.reshape(-1, 2), (columns, rows))
    spacing = _grid_spacing_px(coarse_uv, (columns, rows))
    half_window, sigma = refinement(spacing)
    height, width = grey.shape
    if not all(inside(uv, width, height, half_window + 1) for uv in coarse_uv):
        # A corner's refinement window would run off the image.
        return ChessboardDetection(DetectionStatus.CUT, None, (columns, rows))
    corners = refine_corners(grey, coarse_uv, half_window, sigma)
    corners.setflags(write=False)
    return ChessboardDetection(DetectionStatus.FOUND, corners, (columns, rows), spacing)


def refinement(spacing_px: float) -> tuple[int, float]:
    """cornerSubPix's half window, px, and the blur's sigma, px, for corners ``spacing_px``
    apart: a third and an eighth of a square, within 2-7 and 0.8-2.5 px."""
    half_window = int(np.clip(round(spacing_px / 3.0), 2, 7))
    sigma = float(np.clip(spacing_px / 8.0, 0.8, 2.5))
    return half_window, sigma


def _junctions_at_border(grey: np.ndarray, min_contrast: float, min_count: int = 3) -> bool:
    """Whether several X-junctions are visible, one of them near the border."""
    response = junction_response(cv2.GaussianBlur(grey, (0, 0), 1.0))
    peaks = junction_peaks(response, 8.0 * min_contrast, suppression_px=4)
    if not min_count <= len(peaks) <= 10_000:
        return False
    # Nearest-neighbour spacing of the junctions: about one square.
    deltas = np.linalg.norm(peaks[:, None, :] - peaks[None, :, :], axis=-1)
    np.fill_diagonal(deltas, np.inf)
    square = float(np.median(deltas.min(axis=1)))
    height, width = grey.shape
    margin = 1.5 * square
    return bool(
        np.any(
            (peaks[:, 0] < margin)
            | (peaks[:, 1] < margin)
            | (peaks[:, 0] > width - 1 - margin)
            | (peaks[:, 1] > height - 1 - margin)
        )
    )
