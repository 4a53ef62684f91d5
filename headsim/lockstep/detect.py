"""A marker's centroid in many images at once: :func:`headsim.vision.markers.find_marker`'s
answers, with the per-image work done over the whole stack.

One colour-weight pass and one threshold serve every image, and each image's pixels of
the colour are bounded by reductions over the stack; an image with none is LOST at once.
Only the few pixels around each image's blob are then labelled: an image whose only
blob touches its border is CUT; one with a single blob gets its rim-weighted centroid and
:func:`~headsim.vision.markers.asymmetry`'s shape test over the same window, in the same
order, as ``find_marker``; an image with several pieces of the colour goes to
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
from headsim.vision.threads import serial_opencv

_RIM = np.ones((3, 3), np.uint8)


def colour_weight_u8(images: np.ndarray, colour: str) -> np.ndarray:
    """(..., H, W) uint8: min(on channels) - max(off channels), saturating at 0 (the
    weight ``find_marker`` thresholds, times 255), for a stack of RGB images (..., H, W, 3)."""
    if colour not in COLOURS:
        raise ValueError(f"unknown marker colour {colour!r}; allowed: {', '.join(COLOURS)}")
    mask = COLOURS[colour]
    if images.size == 0:
        return np.zeros(images.shape[:-1], np.uint8)
    shape = images.shape[:-1]
    channels = cv2.split(np.ascontiguousarray(images).reshape(-1, shape[-1], 3))
    on_channels = [c for c, m in zip(channels, mask, strict=True) if m]
    off_channels = [c for c, m in zip(channels, mask, strict=True) if not m]
    on = on_channels[0] if len(on_channels) == 1 else cv2.min(*on_channels)
    if not off_channels:
        return np.asarray(on).reshape(shape)
    off = off_channels[0] if len(off_channels) == 1 else cv2.max(*off_channels)
    return np.asarray(cv2.subtract(on, off)).reshape(shape)


def find_markers_stacked(
    images: np.ndarray, colour: str, threshold: float = 0.2
) -> list[Detection]:
    """``find_marker(image, colour, threshold)`` for each image of ``images`` (m, H, W, 3)."""
    if images.ndim != 4 or images.shape[-1] != 3 or images.dtype != np.uint8:
        raise ValueError(f"images must be (m, H, W, 3) uint8, got {images.shape} {images.dtype}")
    count, height, width = images.shape[:3]
    if count == 0:
        return []
    weight = colour_weight_u8(images, colour)
    inked = weight > threshold * 255.0
    rows: np.ndarray = np.any(inked, axis=2)
    columns: np.ndarray = np.any(inked, axis=1)
    # Each image's first and last inked row and column, for the whole stack at once.
    top, bottom = rows.argmax(axis=1), height - 1 - rows[:, ::-1].argmax(axis=1)
    left, right = columns.argmax(axis=1), width - 1 - columns[:, ::-1].argmax(axis=1)
    out = [Detection(DetectionStatus.LOST, None, 0.0)] * count
    with serial_opencv():  # each image's blob window: a few hundred pixels
        for image in np.flatnonzero(rows.any(axis=1)).tolist():
            # Every piece of the colour, and a pixel around them for the rim.
            y0, y1 = max(int(top[image]) - 1, 0), min(int(bottom[image]) + 2, height)
            x0, x1 = max(int(left[image]) - 1, 0), min(int(right[image]) + 2, width)
            binary = inked[image, y0:y1, x0:x1].astype(np.uint8)
            pieces, _, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=8)
            if pieces > 2:
                out[image] = find_marker(images[image], colour, threshold)
                continue
            x, y, w, h = (int(stats[1, k]) for k in range(4))
            x, y = x + x0, y + y0
            if x == 0 or y == 0 or x + w >= width or y + h >= height:
                area = float(stats[1, cv2.CC_STAT_AREA])
                out[image] = Detection(DetectionStatus.CUT, None, area)
                continue
            rim = cv2.dilate(binary, _RIM, borderType=cv2.BORDER_CONSTANT, borderValue=0)
            rimmed = np.where(rim > 0, weight[image, y0:y1, x0:x1], 0)
            out[image] = _single(rimmed, x - 1 - x0, y - 1 - y0, (x0, y0), (w + 2, h + 2))
    return out


def _single(
    rimmed: np.ndarray, left: int, top: int, origin: tuple[int, int], size: tuple[int, int]
) -> Detection:
    """The one blob's detection from its rim-weighted window (``size`` px from (``left``,
    ``top``) of ``rimmed``, whose pixel (0, 0) is the image's ``origin``), measured as
    ``find_marker`` measures it (the same sums in the same order), with its shape test."""
    wts = rimmed[top : top + size[1], left : left + size[0]].astype(np.float64) / 255.0
    total = float(wts.sum())
    x0, y0 = origin[0] + left, origin[1] + top
    us = np.arange(x0, x0 + size[0])[None, :]  # find_marker's mgrid, broadcast
    vs = np.arange(y0, y0 + size[1])[:, None]
    u = float((wts * us).sum() / total)
    v = float((wts * vs).sum() / total)
    if total >= MIN_SHAPE_AREA_PX and asymmetry(wts, u - x0, v - y0) > MAX_ASYMMETRY:
        return Detection(DetectionStatus.OCCLUDED, None, total)
    return Detection(DetectionStatus.FOUND, (u, v), total)


__all__ = ["colour_weight_u8", "find_markers_stacked"]
