"""Coloured markers (:func:`find_marker`, :func:`find_markers`), pixels.

A pixel's weight is how much its "on" channels exceed its "off" channels
(:func:`colour_weight`); against any grey background it equals the
marker's coverage of the pixel, so anti-aliased edges count partly and
the weighted centroid is sub-pixel.

What can be told from one image: LOST -- no pixel of the colour; CUT --
the blob touches the image border; OCCLUDED -- the blob is split into
nearby pieces (something thin in front of it), its outline is not a whole
ellipse (:func:`asymmetry`: something in front hides a piece of it), or,
when the caller gives the area it expects (e.g. the previous unoccluded
detection's ``area_px``), it is much smaller than that.  What cannot be
told: a marker hidden completely reads LOST (as if absent); a sliver
hidden (under about a fifth of the diameter) reads FOUND with its centroid
moved by a fraction of a pixel, and so does what is left of a blob under
6 px^2; a blob cut by the black, invalid corners of a strongly distorted
image looks like one on the background and is not flagged.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import cv2
import numpy as np

from headsim.vision.detection import Detection, DetectionStatus, check_rgb

#: Named marker colours: which RGB channels are "on".
COLOURS = {
    "red": (1, 0, 0),
    "green": (0, 1, 0),
    "blue": (0, 0, 1),
    "yellow": (1, 1, 0),
    "magenta": (1, 0, 1),
    "cyan": (0, 1, 1),
}


def _check_colour(colour: str) -> tuple[int, int, int]:
    if colour not in COLOURS:
        raise ValueError(f"unknown marker colour {colour!r}; allowed: {', '.join(COLOURS)}")
    return COLOURS[colour]


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
    check_rgb(image)
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
    if total >= MIN_SHAPE_AREA_PX and asymmetry(wts, u - x0, v - y0) > MAX_ASYMMETRY:
        return Detection(DetectionStatus.OCCLUDED, None, total)
    return Detection(DetectionStatus.FOUND, (u, v), total)


#: The most :func:`asymmetry` of a blob taken for a whole marker.  Whole markers on
#: renders of every preset (noise_std 0 and 4, 0.12-2.2 m, across the image): at most
#: 0.054 from 6 px^2 up, 0.041 from 12 px^2 up.  Half a marker hidden: 0.07-0.08 at
#: 6-15 px^2, 0.1-0.2 from a radius of 3 px up (tests/vision/test_markers.py).
MAX_ASYMMETRY = 0.06
#: Blobs smaller than this are too small to tell their shape (whole ones reach 0.07).
MIN_SHAPE_AREA_PX = 6.0
#: The Gaussian that softens a blob before it is turned, px.
_SOFTEN_PX = 0.7
#: ... and a hard-edged one (rendered without anti-aliasing, ``RenderFidelity(0, 1)``:
#: no pixel partly covered), whose staircase edges alone reach 0.14 at 0.7 px: at
#: 1.3 px whole ones stay under 0.053 (80 poses at 0.4-1.6 m), while half a marker
#: hidden still reads 0.2 from about 35 px^2 up.
_SOFTEN_HARD_EDGE_PX = 1.3
#: A blob whose partly covered pixels (weights 0.1-0.9) are fewer than this share of
#: its pixels has hard edges: anti-aliased renders give 0.19-0.75, aliased ones 0.
_HARD_EDGE_SHARE = 0.1


def asymmetry(weights: np.ndarray, u: float, v: float) -> float:
    """How far a blob (weights (H, W)) is from looking the same turned by half a turn about
    its centroid (``u``, ``v``, in the window's pixels): sum |w - w turned| over twice
    the sum of w, 0 for a symmetric one.

    A whole marker images as an ellipse, blurred by anti-aliasing and the lens
    model's resampling, and symmetric about its centre however blurred; a marker
    partly hidden is a disc with a piece missing, which is not.  Both copies are
    softened by a Gaussian (linear interpolation of a sharp edge is itself
    uneven; more where the render has no anti-aliasing, whose staircase edges are
    uneven too) and moved half-way each, so that both are interpolated alike.
    """
    h, w = weights.shape
    inked = weights[weights > 0.02]
    partial = np.count_nonzero((inked > 0.1) & (inked < 0.9)) / inked.size if inked.size else 0.0
    soften = _SOFTEN_HARD_EDGE_PX if partial < _HARD_EDGE_SHARE else _SOFTEN_PX
    pad = 4  # room for the softening and the moves: the blob stays inside
    padded = cv2.copyMakeBorder(
        weights.astype(np.float32), pad, pad, pad, pad, cv2.BORDER_CONSTANT, value=0.0
    )
    a = cv2.GaussianBlur(padded, (0, 0), soften, borderType=cv2.BORDER_CONSTANT)
    b = cv2.flip(a, -1)
    du, dv = (w - 1) / 2 - u, (h - 1) / 2 - v  # moves the centroid to the middle
    size = (w + 2 * pad, h + 2 * pad)
    shift_a = np.array([[1.0, 0.0, du], [0.0, 1.0, dv]], dtype=np.float32)
    shift_b = np.array([[1.0, 0.0, -du], [0.0, 1.0, -dv]], dtype=np.float32)
    moved_a = cv2.warpAffine(a, shift_a, size, flags=cv2.INTER_LINEAR, borderValue=0.0)
    moved_b = cv2.warpAffine(b, shift_b, size, flags=cv2.INTER_LINEAR, borderValue=0.0)
    return float(np.abs(moved_a - moved_b).sum() / (moved_a.sum() + moved_b.sum()))


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
    when its outline is not a whole ellipse (:func:`asymmetry` above
    :data:`MAX_ASYMMETRY`: partly hidden), or when ``expected_area_px`` is
    given and the weighted area is below ``min_area_fraction`` of it.  Full-frame, about 1 ms at 640 x 480.
    """
    _check_colour(colour)
    check_rgb(image)
    weight = _weight_u8(tuple(cv2.split(image)), colour)
    return _blob_detection(weight, threshold, expected_area_px, min_area_fraction)


@dataclass(frozen=True, eq=False)
class MarkerDetector:
    """The detector of the largest blob of ``colour`` (:func:`find_marker`).  A blob: its
    answer is decided by the blob and what lies within one blob size of it, so it may
    look at windows and previews (``finds_blob``).  Compared by identity: one target."""

    colour: str

    @property
    def finds_blob(self) -> bool:
        return True

    def __call__(self, image: np.ndarray) -> Detection:
        return find_marker(image, self.colour)


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
    check_rgb(image)
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
