"""What every detector returns: the status vocabulary and a point detection.

Pixel coordinates ``(u, v)`` are OpenCV's: u right, v down, the centre of
pixel (row r, column c) at ``(c, r)``.  Images are RGB uint8 (H, W, 3), as
:meth:`headsim.sim.simulator.HeadSim.render` returns them.

Three kinds of target (:mod:`headsim.vision.markers`,
:mod:`headsim.vision.chessboard`, :mod:`headsim.vision.crosses`), one status
vocabulary (:class:`DetectionStatus`): a target that is absent, cut by the
image border or occluded is reported as such, with no position -- never guessed.

Sub-pixel accuracy is limited by the renderer: MuJoCo's 4x multisampling
quantises an edge's coverage to quarter pixels, so an edge parallel to the
pixel rows or columns is placed only to +-0.125 px, whatever the detector
(a corner of two such edges: 0.10 px RMS, up to 0.18 px).  Measured on
renders of both presets at (offsamples 4, supersample 1) (tests/vision/):
marker centroids 0.04-0.06 px RMS, also with noise_std = 2; chessboard
corners 0.05 px RMS on a board turned in the image, 0.10 px on one square to
the pixel grid; cross points 0.065 px RMS, max 0.18 px.  The default
rendering, (4, 2), renders twice as large and area-averages back, which
halves the floor (docs/how-to/realistic-head.md, rendering fidelity).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, replace

import cv2
import numpy as np


class DetectionStatus(enum.Enum):
    FOUND = "found"
    LOST = "lost"  # nothing of the target in the image
    CUT = "cut"  # the target runs off the image border: its position would be biased
    OCCLUDED = "occluded"  # the target is partly hidden: its position would be biased
    LOW_TEXTURE = "low texture"  # a template too plain to place itself (markerless)
    AMBIGUOUS = "ambiguous"  # a second match nearly as good as the best (markerless)


@dataclass(frozen=True)
class Detection:
    """A detected feature: status, sub-pixel position (u, v) px, area px^2.

    ``uv`` is None unless FOUND.  ``area_px`` is the colour-weighted area of
    the blob (FOUND, OCCLUDED) or its pixel count (CUT), 0 when LOST.
    ``extent_px``: for a feature found as part of a larger pattern (a
    chessboard's corner), the (left, top, right, bottom) px from ``uv`` of
    everything the detector needed to see; None for a blob.  ``pattern_uv``:
    where that detection found every feature of the pattern, (u, v) px in the
    same pixels as ``uv``, and ``pattern_scale_px`` the pattern's spacing (a
    chessboard's square); None and 0 otherwise (a feature found alone).
    ``score`` and ``ambiguity``: a correlation match's peak NCC and second-best / best
    peak ratio, given whatever the status (:mod:`headsim.vision.correspondence`);
    None for a detector that does not correlate.
    """

    status: DetectionStatus
    uv: tuple[float, float] | None
    area_px: float
    extent_px: tuple[float, float, float, float] | None = None
    pattern_uv: tuple[tuple[float, float], ...] | None = None
    pattern_scale_px: float = 0.0
    score: float | None = None
    ambiguity: float | None = None

    def moved(self, du: float, dv: float) -> Detection:
        """This detection in pixels offset by (du, dv) (a window's in the full frame's)."""
        uv = None if self.uv is None else (self.uv[0] + du, self.uv[1] + dv)
        pattern = (
            None if self.pattern_uv is None else tuple((u + du, v + dv) for u, v in self.pattern_uv)
        )
        return replace(self, uv=uv, pattern_uv=pattern)

    @property
    def found(self) -> bool:
        return self.status is DetectionStatus.FOUND


def check_rgb(image: np.ndarray) -> None:
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(
            f"expected an RGB uint8 image (H, W, 3), got {image.dtype} {tuple(image.shape)}"
        )


def to_grey(image: np.ndarray) -> np.ndarray:
    """Grey levels of an RGB uint8 image, or of a single-channel image, uint8."""
    if image.ndim == 2 and image.dtype == np.uint8:
        return image
    check_rgb(image)
    return cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
