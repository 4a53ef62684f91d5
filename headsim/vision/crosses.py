"""The cross point of two blocks (:func:`find_cross_point`), pixels.

The paper's target (Fig. 8): two black squares touching at one corner on
a white plate, i.e. an X-junction.  Candidates come from the ChESS
response (Bennett and Lasenby, 2014) over the whole image; the best is
refined like a chessboard corner and checked for the point symmetry of
an X on rings sized by the cross (OCCLUDED when something covers part
of it; see :func:`find_cross_point`).  A cross point outside
the image, or one whose centre is covered, reads LOST even when parts of
the blocks are visible.  The blocks need about 10 px on a side.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from headsim.vision.detection import DetectionStatus, to_grey
from headsim.vision.junctions import (
    inside,
    junction_asymmetry,
    junction_extent_px,
    junction_response,
    junction_size_px,
    refine_corners,
)


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


#: Ring radii on which a cross point's point symmetry is checked, px: every one
#: from the first up to the reach the cross's size allows (see find_cross_point).
_SYMMETRY_RADII = (4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0)


#: The symmetry rings reach this fraction of the cross's size (its longest dark
#: run): about half of a square's side, whatever the view.
_SYMMETRY_REACH = 0.35


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
    fidelity (tests/vision/test_crosses.py); a cover of the same grey as the sector
    it lies on, or farther out, may not be.
    """
    grey = to_grey(image)
    height, width = grey.shape
    border = 2 * radius_px if border_px is None else int(border_px)
    response = junction_response(cv2.GaussianBlur(grey, (0, 0), 1.0), radius_px)
    v0, u0 = divmod(int(np.argmax(response)), width)
    contrast = max(0.0, float(response[v0, u0]) / 8.0)
    if contrast < min_contrast:
        return CrossPointDetection(DetectionStatus.LOST, None, contrast)
    seed = np.array([u0, v0], dtype=np.float64)
    if not inside(seed, width, height, border):
        return CrossPointDetection(DetectionStatus.CUT, None, contrast)
    extent = junction_extent_px(grey, seed)
    if extent < 1.4 * radius_px:  # a junction, but its pattern breaks off at once
        return CrossPointDetection(DetectionStatus.OCCLUDED, None, contrast)
    half_window = int(np.clip(round(0.4 * extent), 3, 10))
    uv = refine_corners(grey, seed, half_window, float(np.clip(half_window / 3.5, 1.0, 3.0)))[0]
    if np.linalg.norm(uv - seed) > radius_px:
        return CrossPointDetection(DetectionStatus.LOST, None, contrast)
    if not inside(uv, width, height, border + half_window):
        return CrossPointDetection(DetectionStatus.CUT, None, contrast)
    # Rings inside the squares, sized by the longest dark run, which a cover
    # on one side cannot shorten (not by the extent, which it can).
    reach = _SYMMETRY_REACH * junction_size_px(grey, uv)
    radii = [r for r in _SYMMETRY_RADII if r <= max(reach, _SYMMETRY_RADII[0])]
    if max(junction_asymmetry(grey, uv, r) for r in radii) > max_asymmetry:
        return CrossPointDetection(DetectionStatus.OCCLUDED, None, contrast)
    return CrossPointDetection(DetectionStatus.FOUND, (float(uv[0]), float(uv[1])), contrast)
