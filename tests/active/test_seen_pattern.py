"""What the eye servo keeps of a pattern it saw, and the preview that places it after a
long move (pure arithmetic on exact synthetic detections)."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.look import (
    PREVIEW_MIN_SPACING_PX,
    SeenPattern,
    preview_binning,
    remembered,
)
from headsim.vision.detection import Detection, DetectionStatus


def _board(corners: np.ndarray, index: int, spacing: float) -> Detection:
    """A whole-board detection of feature ``index``: its box one square beyond the corners."""
    u, v = corners[index]
    low, high = corners.min(axis=0) - spacing, corners.max(axis=0) + spacing
    return Detection(
        DetectionStatus.FOUND,
        (float(u), float(v)),
        1.0,
        (low[0] - u, low[1] - v, high[0] - u, high[1] - v),
        pattern_uv=tuple((float(a), float(b)) for a, b in corners),
        pattern_scale_px=spacing,
    )


def _grid(origin: tuple[float, float], spacing: float) -> np.ndarray:
    j, i = np.divmod(np.arange(12), 4)
    return np.column_stack([origin[0] + spacing * i, origin[1] + spacing * j])


@pytest.mark.parametrize("binning", [2, 4])
def test_a_preview_sight_is_the_full_frames_scaled_to_pixel_centres(binning: int) -> None:
    # A board whose corners sit at binned pixel centres: full-frame pixels b i + (b - 1) / 2.
    binned = _grid((40.0, 30.0), 14.0)
    seen = SeenPattern.from_preview(_board(binned, 5, 14.0), binning)
    assert seen is not None
    full = _grid(
        (binning * 40.0 + (binning - 1) / 2, binning * 30.0 + (binning - 1) / 2), 14.0 * binning
    )
    np.testing.assert_allclose(seen.features, full, rtol=0, atol=1e-12)
    assert seen.spacing_px == pytest.approx(14.0 * binning, abs=1e-12)
    # The box: one full-frame square beyond the corners, about the binned pixels' centres.
    offset = (binning - 1) / 2
    expected_box = binning * np.array([26.0, 16.0, 96.0, 72.0]) + offset
    np.testing.assert_allclose(seen.box, expected_box, rtol=0, atol=1e-12)


def test_a_lost_preview_places_nothing() -> None:
    assert SeenPattern.from_preview(Detection(DetectionStatus.LOST, None, 0.0), 2) is None


def test_the_feature_found_alone_moves_the_whole_pattern() -> None:
    corners = _grid((100.0, 80.0), 28.0)
    kept = remembered(None, _board(corners, 0, 28.0), None)
    assert kept is not None
    alone = Detection(DetectionStatus.FOUND, (157.25, 136.5), 1.0, (-18.0, -18.0, 18.0, 18.0))
    moved = remembered(kept, alone, 5)  # feature 5 was at (128, 108)
    assert moved is not None
    np.testing.assert_allclose(moved.features - kept.features, [[29.25, 28.5]] * 12, atol=1e-12)
    np.testing.assert_allclose(moved.box - kept.box, [29.25, 28.5, 29.25, 28.5], atol=1e-12)
    # A blob's detection keeps no pattern.
    assert remembered(kept, alone, None) is None


@pytest.mark.parametrize(
    ("spacing", "largest", "size", "expected"),
    [
        (28.6, 4, (640, 480), 2),  # 14.3 px squares binned 2 x 2; 7.2 at 4 x 4: too small
        (45.0, 4, (640, 480), 4),  # 11.25 px at 4 x 4
        (45.0, 2, (640, 480), 2),  # no more than the servo's binning
        (19.9, 4, (640, 480), 1),  # 9.95 px at 2 x 2: no preview
        (45.0, 4, (641, 480), 1),  # 2 does not divide the width
        (45.0, 4, (644, 482), 2),  # 2 divides both; 4 does not divide the height
    ],
)
def test_the_preview_binning_keeps_the_pattern_findable(
    spacing: float, largest: int, size: tuple[int, int], expected: int
) -> None:
    b = preview_binning(spacing, largest, size)
    assert b == expected
    assert b == 1 or spacing / b >= PREVIEW_MIN_SPACING_PX
