"""X-junction measurements on exact synthetic images.

Two dark squares touching at one corner (the paper's cross) are drawn with
each pixel's exact area coverage, so the junction's true position is known to
float precision and the sub-pixel figures are strict.
"""

from __future__ import annotations

import numpy as np

from headsim.vision.junctions import (
    inside,
    junction_asymmetry,
    junction_extent_px,
    junction_peaks,
    junction_response,
    junction_score,
    junction_size_px,
    refine_corners,
)

DARK, BRIGHT = 30.0, 230.0


def _coverage(lo: float, hi: float, n: int) -> np.ndarray:
    """Length of [lo, hi] inside each pixel [c - 0.5, c + 0.5], c = 0 .. n - 1."""
    centres = np.arange(n)
    return np.clip(np.minimum(centres + 0.5, hi) - np.maximum(centres - 0.5, lo), 0.0, 1.0)


def cross_image(
    u: float, v: float, side_px: float, width: int = 96, height: int = 80
) -> np.ndarray:
    """Grey uint8 image: squares of ``side_px`` above-left and below-right of (u, v) px."""
    upper = np.outer(_coverage(v - side_px, v, height), _coverage(u - side_px, u, width))
    lower = np.outer(_coverage(v, v + side_px, height), _coverage(u, u + side_px, width))
    return np.round(BRIGHT - (BRIGHT - DARK) * (upper + lower)).astype(np.uint8)


def test_response_peaks_at_the_junction_and_refinement_finds_it_to_subpixel() -> None:
    truth = np.array([40.3, 37.6])
    grey = cross_image(*truth, side_px=20)
    response = junction_response(grey)
    peaks = junction_peaks(response, 8.0 * 40.0, suppression_px=4)
    assert len(peaks) == 1
    assert np.abs(peaks[0] - truth).max() <= 0.5
    # About 8 x the contrast (200 grey levels) at a clean junction.
    assert 600 < response.max() < 1800
    refined = refine_corners(grey, peaks, half_window_px=5, blur_sigma_px=1.5)
    assert refined.shape == (1, 2)
    assert np.linalg.norm(refined[0] - truth) < 0.05


def test_an_edge_and_a_plain_corner_are_not_junctions() -> None:
    edge = np.full((80, 96), BRIGHT, np.uint8)
    edge[:, 48:] = DARK
    assert junction_response(edge)[40, 48] < 0
    assert junction_score(edge, np.array([48.0, 40.0]), 5.0) <= 0
    square = np.round(
        BRIGHT - (BRIGHT - DARK) * np.outer(_coverage(20, 40, 80), _coverage(20, 40, 96))
    )
    assert junction_score(square.astype(np.uint8), np.array([40.0, 40.0]), 5.0) <= 0
    assert len(junction_peaks(junction_response(edge), 8.0 * 40.0, suppression_px=4)) == 0


def test_a_clean_cross_is_point_symmetric_and_a_covered_one_is_not() -> None:
    uv = np.array([40.3, 37.6])
    grey = cross_image(*uv, side_px=20)
    assert junction_score(grey, uv, 5.0) > 0.5
    assert junction_asymmetry(grey, uv, 6.0) < 0.05
    covered = grey.copy()
    covered[38:46, 41:49] = int(BRIGHT)  # a bright patch on the lower square, next to the junction
    assert junction_asymmetry(covered, uv, 6.0) > 0.08  # find_cross_point's default threshold
    uniform = np.full((80, 96), 128, np.uint8)
    assert junction_asymmetry(uniform, uv, 6.0) == 2.0
    assert junction_score(uniform, uv, 6.0) == 0.0


def test_size_is_the_squares_diagonal_and_extent_grows_with_the_squares() -> None:
    uv = np.array([48.0, 40.0])
    extents = []
    for side in (10.0, 20.0, 30.0):
        grey = cross_image(*uv, side_px=side)
        # The dark run along the bisector ends at the square's far corner.
        assert abs(junction_size_px(grey, uv) - side * np.sqrt(2)) <= 1.0
        extents.append(junction_extent_px(grey, uv))
    assert extents == sorted(extents) and extents[0] < extents[-1]
    assert all(0 < e <= s for e, s in zip(extents, (10.0, 20.0, 30.0), strict=True))
    assert junction_size_px(np.full((80, 96), 128, np.uint8), uv) == 0.0
    assert junction_extent_px(np.full((80, 96), 128, np.uint8), uv) == 0.0


def test_inside_keeps_a_border_on_every_side() -> None:
    assert inside(np.array([5.0, 5.0]), 96, 80, 5)
    assert inside(np.array([90.0, 74.0]), 96, 80, 5)
    assert not inside(np.array([4.9, 40.0]), 96, 80, 5)
    assert not inside(np.array([40.0, 74.1]), 96, 80, 5)
    assert not inside(np.array([90.1, 40.0]), 96, 80, 5)
