"""X-junctions, shared by chessboards and the cross point: grey levels, pixels.

An X-junction is where two dark and two bright sectors meet (a chessboard's
inner corner, the paper's cross point).  This module holds the ChESS
response (Bennett and Lasenby, 2014) over an image, its peaks, the
sub-pixel refinement with :func:`cv2.cornerSubPix` on a blurred image, and
the ring measurements at one point: how clean an X it is
(:func:`junction_score`), how point-symmetric (:func:`junction_asymmetry`),
how far its pattern extends (:func:`junction_extent_px`) and its size
(:func:`junction_size_px`).
"""

from __future__ import annotations

import math

import cv2
import numpy as np


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


def refine_corners(
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


def junction_peaks(response: np.ndarray, min_response: float, suppression_px: int) -> np.ndarray:
    """Local maxima (N, 2) (u, v) px of a response map above ``min_response``."""
    size = 2 * suppression_px + 1
    local_max = cv2.dilate(response, np.ones((size, size), np.uint8))
    vs, us = np.nonzero((response >= local_max) & (response > min_response))
    return np.column_stack([us, vs]).astype(np.float64)


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


def inside(uv: np.ndarray, width: int, height: int, border: float) -> bool:
    return bool(border <= uv[0] <= width - 1 - border and border <= uv[1] <= height - 1 - border)
