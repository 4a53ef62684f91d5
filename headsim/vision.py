"""Feature detection on rendered images (OpenCV conventions, pixels).

Coloured markers are found by colour: a pixel's weight is how much its "on"
channels exceed its "off" channels, so anti-aliased edges count partly and the
weighted centroid is sub-pixel.  A target that is absent, or that touches the
image border, is reported as such -- never guessed.
"""

from __future__ import annotations

import enum
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
    LOST = "lost"  # nothing of that colour in the image
    CUT = "cut"  # the blob touches the image border: its centroid would be biased


@dataclass(frozen=True)
class Detection:
    """A detected feature: status, sub-pixel position (u, v) px, area px^2."""

    status: DetectionStatus
    uv: tuple[float, float] | None
    area_px: float

    @property
    def found(self) -> bool:
        return self.status is DetectionStatus.FOUND


def colour_weight(image: np.ndarray, colour: str) -> np.ndarray:
    """Per-pixel weight in [0, 1] of ``colour`` in an RGB uint8 image (H, W, 3)."""
    if colour not in COLOURS:
        raise ValueError(f"unknown marker colour {colour!r}; allowed: {', '.join(COLOURS)}")
    mask = np.array(COLOURS[colour], dtype=bool)
    rgb = image.astype(np.float32)
    on = rgb[..., mask].min(axis=-1)
    off = rgb[..., ~mask].max(axis=-1) if (~mask).any() else np.zeros(on.shape, np.float32)
    return np.clip((on - off) / 255.0, 0.0, 1.0)


def find_marker(image: np.ndarray, colour: str, threshold: float = 0.2) -> Detection:
    """Sub-pixel centroid of the largest blob of ``colour``.

    The centroid is weighted by :func:`colour_weight` over the blob's pixels
    (the weights' anti-aliased edges make it sub-pixel).
    """
    weight = colour_weight(image, colour)
    binary = (weight > threshold).astype(np.uint8)
    count, labels, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=8)
    if count <= 1:
        return Detection(DetectionStatus.LOST, None, 0.0)
    largest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    x, y, w, h = (int(stats[largest, k]) for k in (0, 1, 2, 3))
    # Include the blob's faint anti-aliased rim: dilate by one pixel.
    blob = cv2.dilate((labels == largest).astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    height, width = weight.shape
    if x == 0 or y == 0 or x + w >= width or y + h >= height:
        return Detection(DetectionStatus.CUT, None, float(stats[largest, cv2.CC_STAT_AREA]))
    wts = np.where(blob, weight, 0.0)
    total = float(wts.sum())
    vs, us = np.nonzero(blob)
    u = float((wts[vs, us] * us).sum() / total)
    v = float((wts[vs, us] * vs).sum() / total)
    return Detection(DetectionStatus.FOUND, (u, v), total)
