"""A marker's centroid in many images at once: :func:`headsim.vision.markers.find_marker`'s
answers, with the per-image work done over the whole stack.

The images are stacked one above the other with a blank row between them, so that one
colour-weight pass, one threshold and one connected-components call serve them all (no
blob crosses a blank row).  An image with no blob is LOST; one whose only blob touches
its border is CUT; one with a single blob gets its rim-weighted centroid from sums over
the stack, then :func:`~headsim.vision.markers.asymmetry`'s shape test as
``find_marker`` does.  An image with several pieces of the colour goes to
``find_marker`` itself (its largest-blob and nearby-piece rules), so every answer is
``find_marker``'s.
"""

from __future__ import annotations

import cv2
import numpy as np

from headsim.vision.detection import Detection, DetectionStatus
from headsim.vision.markers import (
    COLOURS,
    MAX_ASYMMETRY,
    MIN_SHAPE_AREA_PX,
    asymmetry,
    find_marker,
)

_RIM = np.ones((3, 3), np.uint8)


def colour_weight_u8(images: np.ndarray, colour: str) -> np.ndarray:
    """(..., H, W) uint8: min(on channels) - max(off channels), saturating at 0 (the
    weight ``find_marker`` thresholds, times 255), for a stack of RGB images (..., H, W, 3)."""
    if colour not in COLOURS:
        raise ValueError(f"unknown marker colour {colour!r}; allowed: {', '.join(COLOURS)}")
    mask = COLOURS[colour]
    on = np.min(images[..., [k for k in range(3) if mask[k]]], axis=-1)
    off_channels = [k for k in range(3) if not mask[k]]
    if not off_channels:
        return on
    off = np.max(images[..., off_channels], axis=-1)
    return np.where(on > off, on - off, 0).astype(np.uint8)


def find_markers_stacked(
    images: np.ndarray, colour: str, threshold: float = 0.2
) -> list[Detection]:
    """``find_marker(image, colour, threshold)`` for each image of ``images`` (m, H, W, 3)."""
    if images.ndim != 4 or images.shape[-1] != 3 or images.dtype != np.uint8:
        raise ValueError(f"images must be (m, H, W, 3) uint8, got {images.shape} {images.dtype}")
    count, height, width = images.shape[:3]
    if count == 0:
        return []
    rows = height + 1  # each image and a blank row under it
    weight = np.zeros((count, rows, width), np.uint8)
    weight[:, :height] = colour_weight_u8(images, colour)
    flat = weight.reshape(count * rows, width)
    binary = (flat > threshold * 255.0).astype(np.uint8)
    n_labels, _, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=8)
    pieces = np.zeros(count, np.int64)
    owner = stats[1:, cv2.CC_STAT_TOP] // rows  # the image each blob lies in
    np.add.at(pieces, owner, 1)
    # The blob and a one-pixel rim around it: the dilated mask (a blob off the border
    # never reaches the blank row or the next image).
    rim = cv2.dilate(binary, _RIM, borderType=cv2.BORDER_CONSTANT, borderValue=0)
    rimmed = np.where(rim > 0, flat, 0).reshape(count, rows, width)
    out = [Detection(DetectionStatus.LOST, None, 0.0)] * count
    for label in range(1, n_labels):
        image = int(owner[label - 1])
        if pieces[image] > 1:
            continue
        x, y, w, h = (int(stats[label, k]) for k in range(4))
        y -= image * rows
        if x == 0 or y == 0 or x + w >= width or y + h >= height:
            area = float(stats[label, cv2.CC_STAT_AREA])
            out[image] = Detection(DetectionStatus.CUT, None, area)
        else:
            out[image] = _single(rimmed[image], x - 1, y - 1, x + w + 1, y + h + 1)
    for crowded in np.flatnonzero(pieces > 1):
        out[int(crowded)] = find_marker(images[crowded], colour, threshold)
    return out


def _single(rimmed: np.ndarray, x0: int, y0: int, x1: int, y1: int) -> Detection:
    """The one blob's detection from its rim-weighted window, as ``find_marker`` measures
    it (the same sums in the same order) with its shape test."""
    wts = rimmed[y0:y1, x0:x1].astype(np.float64) / 255.0
    total = float(wts.sum())
    vs, us = np.mgrid[y0:y1, x0:x1]
    u = float((wts * us).sum() / total)
    v = float((wts * vs).sum() / total)
    if total >= MIN_SHAPE_AREA_PX and asymmetry(wts, u - x0, v - y0) > MAX_ASYMMETRY:
        return Detection(DetectionStatus.OCCLUDED, None, total)
    return Detection(DetectionStatus.FOUND, (u, v), total)


__all__ = ["colour_weight_u8", "find_markers_stacked"]
