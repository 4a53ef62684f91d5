"""Feature detection on rendered images (OpenCV conventions, pixels).

Pixel coordinates ``(u, v)`` are OpenCV's: u right, v down, the centre of
pixel (row r, column c) at ``(c, r)``.  Images are RGB uint8 (H, W, 3), as
:meth:`headsim.sim.simulator.HeadSim.render` returns them.

Three kinds of target, one status vocabulary (:class:`DetectionStatus`): a
target that is absent, cut by the image border or occluded is reported as
such, with no position -- never guessed.

Coloured markers (:func:`find_marker`, :func:`find_markers`)
    A pixel's weight is how much its "on" channels exceed its "off" channels
    (:func:`colour_weight`); against any grey background it equals the
    marker's coverage of the pixel, so anti-aliased edges count partly and
    the weighted centroid is sub-pixel.

    What can be told from one image: LOST -- no pixel of the colour; CUT --
    the blob touches the image border; OCCLUDED -- the blob is split into
    nearby pieces (something thin in front of it), or, when the caller gives
    the area it expects (e.g. the previous unoccluded detection's
    ``area_px``), it is much smaller than that.  What cannot be told: a
    marker hidden completely reads LOST (as if absent); a marker partly
    hidden behind a straight edge, with no expected area, is a smaller convex
    blob and reads FOUND with a biased centroid; a blob cut by the black,
    invalid corners of a strongly distorted image looks like one on the
    background and is not flagged.

Chessboards (:func:`find_chessboard`)
    OpenCV finds the inner corners; they are refined with
    :func:`cv2.cornerSubPix` on a Gaussian-blurred image (the blur makes the
    gradient profile symmetric, removing the ~0.06 px bias the raw 1-px edge
    ramp gives) and put into a fixed order (see :class:`ChessboardDetection`).
    An incomplete board is CUT when X-junctions reach the image border, else
    LOST: a board partly hidden inside the image is not told from one OpenCV
    cannot find.

Cross points (:func:`find_cross_point`)
    The paper's target (Fig. 8): two black squares touching at one corner on
    a white plate, i.e. an X-junction.  Candidates come from the ChESS
    response (Bennett and Lasenby, 2014) over the whole image; the best is
    refined like a chessboard corner and checked for the point symmetry of
    an X on rings sized by the cross (OCCLUDED when something covers part
    of it; see :func:`find_cross_point`).  A cross point outside
    the image, or one whose centre is covered, reads LOST even when parts of
    the blocks are visible.  The blocks need about 10 px on a side.

Sub-pixel accuracy is limited by the renderer: MuJoCo's 4x multisampling
quantises an edge's coverage to quarter pixels, so an edge parallel to the
pixel rows or columns is placed only to +-0.125 px, whatever the detector
(a corner of two such edges: 0.10 px RMS, up to 0.18 px).  Measured on
renders of both presets at (offsamples 4, supersample 1)
(tests/vision/test_detect.py): marker centroids 0.04-0.06 px RMS, also with
noise_std = 2; chessboard corners 0.05 px RMS on a board turned in the
image, 0.10 px on one square to the pixel grid; cross points 0.065 px RMS,
max 0.18 px.  The default rendering, (4, 2), renders twice as large and
area-averages back, which halves the floor (README, rendering fidelity).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import cv2
import numpy as np

#: Named marker colours: which RGB channels are "on".
COLOURS = {
    "red": (1, 0, 0),
    "green": (0, 1, 0),
    "blue": (0, 0, 1),
    "yellow": (1, 1, 0),
    "magenta": (1, 0, 1),
    "cyan": (0, 1, 1),
}


class DetectionStatus(enum.Enum):
    FOUND = "found"
    LOST = "lost"  # nothing of the target in the image
    CUT = "cut"  # the target runs off the image border: its position would be biased
    OCCLUDED = "occluded"  # the target is partly hidden: its position would be biased


@dataclass(frozen=True)
class Detection:
    """A detected feature: status, sub-pixel position (u, v) px, area px^2.

    ``uv`` is None unless FOUND.  ``area_px`` is the colour-weighted area of
    the blob (FOUND, OCCLUDED) or its pixel count (CUT), 0 when LOST.
    ``extent_px``: for a feature found as part of a larger pattern (a
    chessboard's corner), the (left, top, right, bottom) px from ``uv`` of
    everything the detector needed to see; None for a blob.
    """

    status: DetectionStatus
    uv: tuple[float, float] | None
    area_px: float
    extent_px: tuple[float, float, float, float] | None = None

    @property
    def found(self) -> bool:
        return self.status is DetectionStatus.FOUND


# -- coloured markers ---------------------------------------------------------


def _check_colour(colour: str) -> tuple[int, int, int]:
    if colour not in COLOURS:
        raise ValueError(f"unknown marker colour {colour!r}; allowed: {', '.join(COLOURS)}")
    return COLOURS[colour]


def _check_rgb(image: np.ndarray) -> None:
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(
            f"expected an RGB uint8 image (H, W, 3), got {image.dtype} {tuple(image.shape)}"
        )


def _weight_u8(channels: tuple[np.ndarray, ...], colour: str) -> np.ndarray:
    """:func:`colour_weight` times 255 as uint8 (exact: integer, saturating)."""
    mask = _check_colour(colour)
    on_channels = [c for c, m in zip(channels, mask, strict=True) if m]
    off_channels = [c for c, m in zip(channels, mask, strict=True) if not m]
    on = on_channels[0] if len(on_channels) == 1 else cv2.min(*on_channels)
    if not off_channels:
        return on.copy()
    off = off_channels[0] if len(off_channels) == 1 else cv2.max(*off_channels)
    return cv2.subtract(on, off)


def colour_weight(image: np.ndarray, colour: str) -> np.ndarray:
    """Per-pixel weight in [0, 1] of ``colour`` in an RGB uint8 image (H, W, 3).

    min(on channels) - max(off channels), clipped at 0, over 255: for a
    marker of that colour blended with any grey, the marker's pixel coverage.
    """
    _check_colour(colour)
    _check_rgb(image)
    return _weight_u8(tuple(cv2.split(image)), colour).astype(np.float32) / 255.0


def _blob_detection(
    weight: np.ndarray,
    threshold: float,
    expected_area_px: float | None,
    min_area_fraction: float,
) -> Detection:
    """Classify and measure the largest blob of a uint8 weight image (see find_marker)."""
    binary = (weight > threshold * 255.0).astype(np.uint8)
    count, labels, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=8)
    if count <= 1:
        return Detection(DetectionStatus.LOST, None, 0.0)
    areas = stats[1:, cv2.CC_STAT_AREA]
    largest = 1 + int(np.argmax(areas))
    x, y, w, h = (int(stats[largest, k]) for k in range(4))
    height, width = weight.shape
    if x == 0 or y == 0 or x + w >= width or y + h >= height:
        return Detection(DetectionStatus.CUT, None, float(stats[largest, cv2.CC_STAT_AREA]))
    # The blob's pixels and its faint anti-aliased rim (one pixel around it),
    # inside a window one pixel larger than its bounding box (never clipped:
    # the blob does not touch the border).
    x0, y0, x1, y1 = x - 1, y - 1, x + w + 1, y + h + 1
    blob = (labels[y0:y1, x0:x1] == largest).astype(np.uint8)
    rim = cv2.dilate(blob, np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT, borderValue=0)
    wts = np.where(rim > 0, weight[y0:y1, x0:x1], 0).astype(np.float64) / 255.0
    total = float(wts.sum())
    if _has_nearby_piece(stats, largest) or (
        expected_area_px is not None and total < min_area_fraction * expected_area_px
    ):
        return Detection(DetectionStatus.OCCLUDED, None, total)
    vs, us = np.mgrid[y0:y1, x0:x1]
    u = float((wts * us).sum() / total)
    v = float((wts * vs).sum() / total)
    return Detection(DetectionStatus.FOUND, (u, v), total)


def _has_nearby_piece(stats: np.ndarray, largest: int) -> bool:
    """Whether another blob lies within one blob size of the largest one's bounding box."""
    x, y, w, h = (int(stats[largest, k]) for k in range(4))
    gap = max(w, h)
    for label in range(1, len(stats)):
        if label == largest:
            continue
        bx, by, bw, bh = (int(stats[label, k]) for k in range(4))
        dx = max(bx - (x + w), x - (bx + bw), 0)
        dy = max(by - (y + h), y - (by + bh), 0)
        if max(dx, dy) <= gap:
            return True
    return False


def find_marker(
    image: np.ndarray,
    colour: str,
    threshold: float = 0.2,
    *,
    expected_area_px: float | None = None,
    min_area_fraction: float = 0.75,
) -> Detection:
    """Sub-pixel centroid (u, v) px of the largest blob of ``colour``.

    The centroid is weighted by :func:`colour_weight` over the blob's pixels
    (weight > ``threshold``) and a one-pixel rim around them, so the
    anti-aliased edge makes it sub-pixel.  Status: LOST when no pixel has the
    colour; CUT when the blob touches the image border; OCCLUDED when another
    piece of the colour lies within one blob size of it (the blob is split),
    or when ``expected_area_px`` is given and the weighted area is below
    ``min_area_fraction`` of it.  Full-frame, about 1 ms at 640 x 480.
    """
    _check_colour(colour)
    _check_rgb(image)
    weight = _weight_u8(tuple(cv2.split(image)), colour)
    return _blob_detection(weight, threshold, expected_area_px, min_area_fraction)


def find_markers(
    image: np.ndarray,
    colours: Mapping[str, str] | Iterable[str],
    threshold: float = 0.2,
    *,
    expected_areas_px: Mapping[str, float] | None = None,
    min_area_fraction: float = 0.75,
) -> dict[str, Detection]:
    """:func:`find_marker` for several labelled markers in one image.

    ``colours`` maps a label (e.g. a body name, ``"object_1"``) to its colour,
    or is a sequence of colours used as their own labels.  Returns label ->
    :class:`Detection`; ``expected_areas_px`` gives expected areas by label.
    Each colour should belong to one object: of two same-coloured objects
    only the larger blob is measured.
    """
    _check_rgb(image)
    if isinstance(colours, str):
        raise ValueError(f"colours must be a mapping or a sequence of colours, got {colours!r}")
    labelled = dict(colours) if isinstance(colours, Mapping) else {c: c for c in colours}
    for colour in labelled.values():
        _check_colour(colour)
    expected = expected_areas_px or {}
    channels = tuple(cv2.split(image))
    return {
        label: _blob_detection(
            _weight_u8(channels, colour), threshold, expected.get(label), min_area_fraction
        )
        for label, colour in labelled.items()
    }


# -- X-junctions: shared by chessboards and the cross point -------------------


def _grey(image: np.ndarray) -> np.ndarray:
    """Grey levels of an RGB uint8 image, or of a single-channel image, uint8."""
    if image.ndim == 2 and image.dtype == np.uint8:
        return image
    _check_rgb(image)
    return cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)


def _ring_offsets(radius: int) -> list[tuple[int, int]]:
    """16 (du, dv) pixel offsets on a circle of ``radius`` px, from +u turning towards +v."""
    return [
        (
            round(radius * math.cos(2 * math.pi * n / 16)),
            round(radius * math.sin(2 * math.pi * n / 16)),
        )
        for n in range(16)
    ]


def junction_response(grey: np.ndarray, radius_px: int = 5) -> np.ndarray:
    """ChESS X-junction response (H, W) float32 of a grey image, grey levels.

    For the 16 samples I_n on a ring of ``radius_px`` around each pixel:
    sum(|I_n + I_n+8 - I_n+4 - I_n+12|, n < 4) - sum(|I_n - I_n+8|, n < 8)
    - 16 |mean(I) - local mean|.  About 8 x the contrast at an X-junction
    (opposite sectors alike, neighbouring ones unlike), negative on edges and
    plain corners.  The image is reflected at its border so the response is
    defined everywhere; within ``radius_px`` of the border it is unreliable.
    """
    g = grey.astype(np.float32)
    r = int(radius_px)
    height, width = g.shape
    padded = cv2.copyMakeBorder(g, r, r, r, r, cv2.BORDER_REFLECT_101)

    def shifted(du: int, dv: int) -> np.ndarray:
        return padded[r + dv : r + dv + height, r + du : r + du + width]

    ring = [shifted(du, dv) for du, dv in _ring_offsets(r)]
    sum_response = sum(np.abs(ring[n] + ring[n + 8] - ring[n + 4] - ring[n + 12]) for n in range(4))
    diff_response = sum(np.abs(ring[n] - ring[n + 8]) for n in range(8))
    ring_mean = sum(ring) / 16.0
    local_mean = (g + shifted(1, 0) + shifted(-1, 0) + shifted(0, 1) + shifted(0, -1)) / 5.0
    return sum_response - diff_response - 16.0 * np.abs(ring_mean - local_mean)


def _refine_corners(
    grey: np.ndarray, seeds_uv: np.ndarray, half_window_px: int, blur_sigma_px: float
) -> np.ndarray:
    """X-junctions (N, 2) px refined with cornerSubPix on a Gaussian-blurred image."""
    blurred = cv2.GaussianBlur(grey.astype(np.float32), (0, 0), blur_sigma_px)
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-4)
    corners = np.ascontiguousarray(seeds_uv, dtype=np.float32).reshape(-1, 1, 2)
    window = (int(half_window_px), int(half_window_px))
    return (
        cv2.cornerSubPix(blurred, corners, window, (-1, -1), criteria)
        .reshape(-1, 2)
        .astype(np.float64)
    )


# -- chessboards --------------------------------------------------------------


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


def _junction_peaks(response: np.ndarray, min_response: float, suppression_px: int) -> np.ndarray:
    """Local maxima (N, 2) (u, v) px of a response map above ``min_response``."""
    size = 2 * suppression_px + 1
    local_max = cv2.dilate(response, np.ones((size, size), np.uint8))
    vs, us = np.nonzero((response >= local_max) & (response > min_response))
    return np.column_stack([us, vs]).astype(np.float64)


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
    grey = _grey(image)
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
    half_window = int(np.clip(round(spacing / 3.0), 2, 7))
    sigma = float(np.clip(spacing / 8.0, 0.8, 2.5))
    height, width = grey.shape
    if not all(_inside(uv, width, height, half_window + 1) for uv in coarse_uv):
        # A corner's refinement window would run off the image.
        return ChessboardDetection(DetectionStatus.CUT, None, (columns, rows))
    corners = _refine_corners(grey, coarse_uv, half_window, sigma)
    corners.setflags(write=False)
    return ChessboardDetection(DetectionStatus.FOUND, corners, (columns, rows))


def _junctions_at_border(grey: np.ndarray, min_contrast: float, min_count: int = 3) -> bool:
    """Whether several X-junctions are visible, one of them near the border."""
    response = junction_response(cv2.GaussianBlur(grey, (0, 0), 1.0))
    peaks = _junction_peaks(response, 8.0 * min_contrast, suppression_px=4)
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


# -- the cross point of two blocks ---------------------------------------------


@dataclass(frozen=True)
class CrossPointDetection:
    """The blocks' cross point: status, sub-pixel (u, v) px, contrast (grey levels).

    ``uv`` is None unless FOUND.  ``contrast`` is the strength of the best
    junction candidate, its ChESS response / 8: about the bright-minus-dark
    difference for a sharp junction, less for a blurred one; 0 for none.
    """

    status: DetectionStatus
    uv: tuple[float, float] | None
    contrast: float

    @property
    def found(self) -> bool:
        return self.status is DetectionStatus.FOUND


def _ring_samples(grey: np.ndarray, uv: np.ndarray, radius_px: float, count: int) -> np.ndarray:
    """Bilinear samples (count,) of ``grey`` on a circle around ``uv``, from +u towards +v."""
    angles = 2 * np.pi * np.arange(count) / count
    map_u = (uv[0] + radius_px * np.cos(angles)).astype(np.float32).reshape(1, -1)
    map_v = (uv[1] + radius_px * np.sin(angles)).astype(np.float32).reshape(1, -1)
    samples = cv2.remap(
        grey.astype(np.float32), map_u, map_v, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT_101
    )
    return samples.reshape(-1).astype(np.float64)


def junction_asymmetry(grey: np.ndarray, uv: np.ndarray, radius_px: float) -> float:
    """How far the ring around ``uv`` is from an X-junction's point symmetry, 0..2.

    Mean |I(a) - I(a + pi)| over the contrast of the ring (90th minus 10th
    percentile): about 0 for two straight edges crossing at ``uv``, larger
    when something covers part of the pattern.
    """
    samples = _ring_samples(grey, uv, radius_px, 64)
    contrast = float(np.percentile(samples, 90) - np.percentile(samples, 10))
    if contrast <= 0:
        return 2.0
    return float(np.abs(samples[:32] - samples[32:]).mean() / contrast)


def junction_score(grey: np.ndarray, uv: np.ndarray, radius_px: float) -> float:
    """ChESS response at ``uv`` on a ring of ``radius_px`` over 8 x the ring's contrast.

    About 1 for a clean X-junction (a little less when edges pass through
    samples), <= 0 for edges, plain corners and uniform patches.
    """
    ring = _ring_samples(grey, uv, radius_px, 16)
    contrast = float(ring.max() - ring.min())
    if contrast <= 0:
        return 0.0
    sum_response = sum(abs(ring[n] + ring[n + 8] - ring[n + 4] - ring[n + 12]) for n in range(4))
    diff_response = sum(abs(ring[n] - ring[n + 8]) for n in range(8))
    return float((sum_response - diff_response) / (8.0 * contrast))


#: Ring radii tried when measuring how far an X-junction's pattern extends, px.
_EXTENT_RADII = (5.0, 7.0, 9.0, 12.0, 15.0, 19.0, 24.0, 30.0)


def junction_extent_px(grey: np.ndarray, uv: np.ndarray, min_score: float = 0.5) -> float:
    """Largest ring radius (from ``_EXTENT_RADII``) up to which ``uv`` looks like a clean X, px.

    About the size of the squares around the junction; 0 if not even the
    smallest ring does.
    """
    extent = 0.0
    for radius in _EXTENT_RADII:
        if junction_score(grey, uv, radius) < min_score:
            break
        extent = radius
    return extent


#: Ring radius on which a junction's sectors are found, px (outside the refinement's blur).
_SECTOR_RING_PX = 5.0
#: How far a sector's run is followed from the junction, px.
_MAX_RUN_PX = 80
#: Ring radii on which a cross point's point symmetry is checked, px: every one
#: from the first up to the reach the cross's size allows (see find_cross_point).
_SYMMETRY_RADII = (4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0)
#: The symmetry rings reach this fraction of the cross's size (its longest dark
#: run): about half of a square's side, whatever the view.
_SYMMETRY_REACH = 0.35


def junction_size_px(grey: np.ndarray, uv: np.ndarray) -> float:
    """Longest run, px, along the bisector of a dark sector of the X-junction at ``uv``.

    The ring of radius ``_SECTOR_RING_PX`` around ``uv`` is split at the
    mid-level of its grey levels (10th and 90th percentiles); from ``uv``
    along the middle of each of its two longest dark arcs, the grey level is
    followed outwards (1 px steps, up to ``_MAX_RUN_PX``) until it reaches
    the mid-level.  For two squares touching at a corner (or a chessboard's
    corner) that is about a square's diagonal: the cross's size in the image.
    Something covering part of the pattern can shorten one run but not make
    the longer one shorter than the square it leaves uncovered.  0 when the
    ring has no dark arc.
    """
    count = 64
    ring = _ring_samples(grey, uv, _SECTOR_RING_PX, count)
    low, high = np.percentile(ring, [10, 90])
    mid = 0.5 * (low + high)
    dark = ring < mid
    if not dark.any() or dark.all():
        return 0.0
    # Circular runs of dark samples, started just after a bright one.
    start = int(np.argmin(dark))
    arcs: list[tuple[int, int]] = []  # (first index, length)
    n = 0
    while n < count:
        if dark[(start + n) % count]:
            first = n
            while n < count and dark[(start + n) % count]:
                n += 1
            arcs.append((start + first, n - first))
        n += 1
    arcs = sorted(arcs, key=lambda arc: arc[1], reverse=True)[:2]
    steps = np.arange(_SECTOR_RING_PX, _MAX_RUN_PX + 1.0)
    longest = 0.0
    for first, length in arcs:
        angle = 2 * np.pi * (first + (length - 1) / 2) / count
        map_u = (uv[0] + steps * np.cos(angle)).astype(np.float32).reshape(1, -1)
        map_v = (uv[1] + steps * np.sin(angle)).astype(np.float32).reshape(1, -1)
        line = cv2.remap(
            grey.astype(np.float32), map_u, map_v, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        ).reshape(-1)
        brighter = np.flatnonzero(line >= mid)
        longest = max(longest, float(steps[brighter[0]] if len(brighter) else steps[-1]))
    return longest


def find_cross_point(
    image: np.ndarray,
    *,
    radius_px: int = 5,
    min_contrast: float = 40.0,
    max_asymmetry: float = 0.08,
    border_px: int | None = None,
) -> CrossPointDetection:
    """Sub-pixel cross point (u, v) px of two dark squares touching at a corner.

    The strongest X-junction in the image (ChESS response on a ring of
    ``radius_px``) is refined with cornerSubPix on the blurred image, with a
    window and blur scaled to how far the junction's pattern extends.
    Status: LOST when no junction reaches ``min_contrast`` grey levels (no
    target, or its centre hidden); CUT when the junction lies within
    ``border_px`` (default: twice the ring radius) plus the refinement
    window's half-size (3-10 px) of the image border;
    OCCLUDED when the junction is there but its pattern breaks off at once,
    or is not point-symmetric (``junction_asymmetry`` above
    ``max_asymmetry`` on any ring: something covers part of the pattern).
    In an image of a chessboard it returns the strongest of its corners.

    Why the symmetry check holds: straight lines through the junction stay
    straight in any perspective view, so two squares touching at a corner
    look exactly point-symmetric about it out to the squares' outer edges
    (lens distortion bends them only at second order).  The rings checked
    are every one of ``_SYMMETRY_RADII`` (4-16 px) up to 0.35 x the cross's
    size, its longest dark run (:func:`junction_size_px`, about a square's
    diagonal, so the rings stay within half a side).  A cover on one side
    cannot shrink that size, so it cannot hide by shrinking the rings the
    check looks at -- which a size from the ChESS score could (the score of
    a partly covered junction dips below its threshold on the ring that
    meets the cover).  Covers within 16 px of the junction, which the
    refinement window (<= 10 px) would feel, are found at every rendering
    fidelity (tests/vision/test_detect.py); a cover of the same grey as the sector
    it lies on, or farther out, may not be.
    """
    grey = _grey(image)
    height, width = grey.shape
    border = 2 * radius_px if border_px is None else int(border_px)
    response = junction_response(cv2.GaussianBlur(grey, (0, 0), 1.0), radius_px)
    v0, u0 = divmod(int(np.argmax(response)), width)
    contrast = max(0.0, float(response[v0, u0]) / 8.0)
    if contrast < min_contrast:
        return CrossPointDetection(DetectionStatus.LOST, None, contrast)
    seed = np.array([u0, v0], dtype=np.float64)
    if not _inside(seed, width, height, border):
        return CrossPointDetection(DetectionStatus.CUT, None, contrast)
    extent = junction_extent_px(grey, seed)
    if extent < 1.4 * radius_px:  # a junction, but its pattern breaks off at once
        return CrossPointDetection(DetectionStatus.OCCLUDED, None, contrast)
    half_window = int(np.clip(round(0.4 * extent), 3, 10))
    uv = _refine_corners(grey, seed, half_window, float(np.clip(half_window / 3.5, 1.0, 3.0)))[0]
    if np.linalg.norm(uv - seed) > radius_px:
        return CrossPointDetection(DetectionStatus.LOST, None, contrast)
    if not _inside(uv, width, height, border + half_window):
        return CrossPointDetection(DetectionStatus.CUT, None, contrast)
    # Rings inside the squares, sized by the longest dark run, which a cover
    # on one side cannot shorten (not by the extent, which it can).
    reach = _SYMMETRY_REACH * junction_size_px(grey, uv)
    radii = [r for r in _SYMMETRY_RADII if r <= max(reach, _SYMMETRY_RADII[0])]
    if max(junction_asymmetry(grey, uv, r) for r in radii) > max_asymmetry:
        return CrossPointDetection(DetectionStatus.OCCLUDED, None, contrast)
    return CrossPointDetection(DetectionStatus.FOUND, (float(uv[0]), float(uv[1])), contrast)


def _inside(uv: np.ndarray, width: int, height: int, border: float) -> bool:
    return bool(border <= uv[0] <= width - 1 - border and border <= uv[1] <= height - 1 - border)
