"""Markerless fixation's image math: a foveal template, found again by normalised
cross-correlation in a small window (tracking, the dominant eye) or in the band the
believed geometry predicts (correspondence, the other eye).

Pure image math on numpy arrays (OpenCV's ``matchTemplate``); pixels are OpenCV's
(:mod:`headsim.vision.detection`).  Correlation runs on a search region of a few
template sizes only, never on a whole image.  Every match carries its score (the peak
NCC) and its ambiguity (the second-best peak over the best), whatever its status, so
that a wrong but confident match stays visible to the caller.

Thresholds (:class:`MatchConfig`) come from the sensor and from seeded pink-noise
distributions (``tests/vision/test_correspondence.py``), not from a test case:

- LOW_TEXTURE: the template's gradient energy, less the noise's own, predicts a
  location spread above ``max_sigma_px`` = 0.05 px at the stated image noise (the
  Cramer-Rao bound of a translation, sigma^2 = 2 sigma_n^2 / (N E), two noisy images
  of N pixels, per-axis gradient energy E, the weaker axis).  The prediction matches
  the measured spread within 20 % on pink noise of 3-10 grey levels std.
- LOST: ``min_score`` = 0.7, the best NCC of a 41 px pink-noise template over a
  window or a 256 px row band without it (at most 0.51 and 0.59 in 80 draws) plus
  0.1; the true match scores 0.97 (noise 2 grey levels), 0.80-0.84 under a 3 %
  scale and 2 degree rotation between the views.
- AMBIGUOUS: ``max_ambiguity`` = 0.9; true matches on pink noise reach 0.6 (0.79
  with a 6 % scale and 4 degree rotation), repetitive stripes 0.99.
"""

from __future__ import annotations

import enum
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from headsim.vision.detection import to_grey

#: A rectangle of an image, (x0, y0, x1, y1) px, x1 and y1 exclusive.
Rect = tuple[int, int, int, int]


class MatchStatus(enum.Enum):
    OK = "ok"
    LOW_TEXTURE = "low texture"  # the template cannot place itself (decided on the template)
    AMBIGUOUS = "ambiguous"  # another peak nearly as good as the best (repetitive texture)
    OCCLUDED = "occluded"  # part of the template matches well, part not at all
    LOST = "lost"  # no peak good enough, or the best one on the search region's rim


@dataclass(frozen=True)
class MatchConfig:
    """Thresholds of a foveal match.

    ``half_px``: the template's half-side (side 2 half + 1).  ``noise_grey``: the
    image noise the head assumes, grey levels (renderer noise and quantisation);
    ``max_sigma_px``: the largest location spread the template's texture may predict
    at that noise (else LOW_TEXTURE).  ``min_score``: the least peak NCC of a match
    (else LOST).  (How each was chosen: the module's docstring.)  ``max_ambiguity``: the largest second-best / best peak ratio (else
    AMBIGUOUS); ``suppression_px``: the second peak is the best local maximum farther
    than this from the best.  ``occluded_quadrant``: a match whose best template
    quadrant scores ``min_score`` or more and whose worst quadrant scores below this
    is OCCLUDED (quadrants with texture of their own only: std of 3 ``noise_grey``).
    """

    half_px: int = 20
    noise_grey: float = 2.0
    max_sigma_px: float = 0.05
    min_score: float = 0.7
    max_ambiguity: float = 0.9
    suppression_px: float = 3.0
    occluded_quadrant: float = 0.3

    def __post_init__(self) -> None:
        if self.half_px < 3:
            raise ValueError(f"half_px must be >= 3, got {self.half_px}")
        if not 0.0 < self.min_score < 1.0 or not 0.0 < self.max_ambiguity <= 1.0:
            raise ValueError("min_score must be in (0, 1) and max_ambiguity in (0, 1]")


@dataclass(frozen=True)
class Template:
    """A foveal patch: grey levels (float32, side 2 half + 1) cut at the whole pixel
    nearest ``uv``, whose reference point ``uv`` lies at ``offset_px`` from the patch's
    centre pixel.  ``sigma_px``: the location spread its texture predicts
    (:func:`predicted_sigma_px`); ``contrast_grey``: its grey-level std."""

    patch: np.ndarray
    uv: tuple[float, float]
    offset_px: tuple[float, float]
    sigma_px: float
    contrast_grey: float

    @property
    def half_px(self) -> int:
        return (self.patch.shape[0] - 1) // 2

    @property
    def normalised(self) -> np.ndarray:
        """The patch, zero-mean and unit-variance (float32)."""
        centred = self.patch - self.patch.mean()
        return (centred / max(float(centred.std()), 1e-6)).astype(np.float32)


@dataclass(frozen=True)
class Match:
    """Where a template was found: ``uv`` px (sub-pixel, in the searched image's pixels
    plus the caller's origin), ``score`` (peak NCC), ``ambiguity`` (second-best peak /
    best; 0 when none), ``status``, and ``shift_px`` the sub-pixel peak's offset from
    its whole pixel.  ``uv`` is given whatever the status (None only when nothing could
    be searched: a region smaller than the template)."""

    status: MatchStatus
    uv: tuple[float, float] | None
    score: float
    ambiguity: float
    template_sigma_px: float

    @property
    def ok(self) -> bool:
        return self.status is MatchStatus.OK


def grey_float(image: np.ndarray) -> np.ndarray:
    """Grey levels of an RGB uint8 (or grey) image, float32."""
    if image.ndim == 2:
        return image.astype(np.float32, copy=False)
    return to_grey(image).astype(np.float32)


def predicted_sigma_px(patch: np.ndarray, noise_grey: float) -> float:
    """The location spread (px, one axis) a patch's texture allows at image noise
    ``noise_grey``: sqrt(2 sigma_n^2 / (N E)), E the mean per-axis squared gradient less
    the noise's own (sigma_n^2 / 2 for central differences).  inf for a flat patch."""
    gx = cv2.Sobel(patch, cv2.CV_32F, 1, 0, ksize=1) / 2.0
    gy = cv2.Sobel(patch, cv2.CV_32F, 0, 1, ksize=1) / 2.0
    inner = (slice(1, -1), slice(1, -1))
    # The weaker axis: a 1-D texture (a ramp, stripes) can place itself only across it.
    energy = min(float(np.mean(gx[inner] ** 2)), float(np.mean(gy[inner] ** 2)))
    signal = energy - 0.5 * noise_grey**2
    if signal <= 0.0:
        return math.inf
    return math.sqrt(2.0 * noise_grey**2 / (patch[inner].size * signal))


def cut_template(
    image: np.ndarray,
    uv: tuple[float, float],
    config: MatchConfig,
    origin_px: tuple[int, int] = (0, 0),
) -> Template:
    """The foveal template of ``image`` around ``uv`` px (whole pixels, no resampling:
    the fraction is kept as ``offset_px``); ``image`` may be a window whose top-left is
    ``origin_px`` in the full frame (``uv`` is full-frame).  Raises ValueError where the
    patch would leave the image."""
    grey = grey_float(image)
    h = config.half_px
    c, r = round(uv[0]) - origin_px[0], round(uv[1]) - origin_px[1]
    if not (h <= c < grey.shape[1] - h and h <= r < grey.shape[0] - h):
        raise ValueError(
            f"uv {uv} is within {h} px of the image border: no {2 * h + 1} px template there"
        )
    patch = grey[r - h : r + h + 1, c - h : c + h + 1].copy()
    return Template(
        patch=patch,
        uv=(float(uv[0]), float(uv[1])),
        offset_px=(float(uv[0] - round(uv[0])), float(uv[1] - round(uv[1]))),
        sigma_px=predicted_sigma_px(patch, config.noise_grey),
        contrast_grey=float(patch.std()),
    )


# -- where to look -------------------------------------------------------------------
@dataclass(frozen=True)
class Band:
    """Where the other eye's point may lie: within ``tolerance_px`` of the polyline
    through ``points_uv`` (px; one point: a disc)."""

    points_uv: tuple[tuple[float, float], ...]
    tolerance_px: float

    def __post_init__(self) -> None:
        if not self.points_uv or self.tolerance_px < 0:
            raise ValueError("a band needs at least one point and tolerance_px >= 0")

    def distance_px(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Distance of points (u, v) px to the polyline, px."""
        pts = np.asarray(self.points_uv, dtype=np.float64)
        best = np.hypot(u - pts[0, 0], v - pts[0, 1])
        for a, b in itertools.pairwise(pts):
            d = b - a
            length2 = float(d @ d)
            t = (
                0.0
                if length2 == 0
                else np.clip(((u - a[0]) * d[0] + (v - a[1]) * d[1]) / length2, 0, 1)
            )
            best = np.minimum(best, np.hypot(u - a[0] - t * d[0], v - a[1] - t * d[1]))
        return best

    def rect(self, image_size: tuple[int, int]) -> Rect | None:
        """The smallest whole-pixel rectangle holding the band, clipped to the image
        (width, height); None where the band misses the image."""
        pts = np.asarray(self.points_uv, dtype=np.float64)
        tol = self.tolerance_px
        x0 = max(math.floor(pts[:, 0].min() - tol), 0)
        y0 = max(math.floor(pts[:, 1].min() - tol), 0)
        x1 = min(math.ceil(pts[:, 0].max() + tol) + 1, image_size[0])
        y1 = min(math.ceil(pts[:, 1].max() + tol) + 1, image_size[1])
        return None if x1 <= x0 or y1 <= y0 else (x0, y0, x1, y1)


def around(uv: tuple[float, float], radius_px: float) -> Band:
    """The disc of ``radius_px`` around a predicted ``uv`` (tracking's band)."""
    return Band(((float(uv[0]), float(uv[1])),), float(radius_px))


def row_band(v_px: float, image_width: int, tolerance_px: float) -> Band:
    """The band along image row ``v_px`` across the whole width, +- ``tolerance_px``:
    where a head that knows no focal length or eye angles looks for camera 1's point in
    camera 2 (eyes on one tilt axis: epipolar lines near the rows; the tolerance holds
    vergence, lens and reference-row differences)."""
    return Band(((0.0, float(v_px)), (float(image_width - 1), float(v_px))), tolerance_px)


def epipolar_band(
    project: Callable[[np.ndarray], np.ndarray],
    ray_cam1: np.ndarray,
    depths_m: Sequence[float] | np.ndarray,
    tolerance_px: float,
) -> Band:
    """The band the believed geometry predicts for camera 1's ray in camera 2: the
    polyline through ``project`` (camera 1 points, (N, 3) m -> camera 2 pixels (N, 2),
    the head's belief, lens included) of ``ray_cam1`` at ``depths_m`` (ascending; more
    depths where the lens bends the line), grown by ``tolerance_px`` (the belief's
    error, px).  Depths whose projection is not finite are left out."""
    ray = np.asarray(ray_cam1, dtype=np.float64)
    ray = ray / np.linalg.norm(ray)
    points = project(np.outer(np.asarray(depths_m, dtype=np.float64), ray))
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    kept = tuple((float(u), float(v)) for u, v in points if np.isfinite(u) and np.isfinite(v))
    if not kept:
        raise ValueError("no depth of the ray projects into camera 2")
    return Band(kept, tolerance_px)


# -- the match -----------------------------------------------------------------------
def _subpixel(ncc: np.ndarray, x: int, y: int) -> tuple[float, float]:
    """The peak of the 2-D quadratic through the 3 x 3 NCC values around (x, y)."""
    n = ncc[y - 1 : y + 2, x - 1 : x + 2].astype(np.float64)
    dx = (n[1, 2] - n[1, 0]) / 2.0
    dy = (n[2, 1] - n[0, 1]) / 2.0
    dxx = n[1, 2] - 2 * n[1, 1] + n[1, 0]
    dyy = n[2, 1] - 2 * n[1, 1] + n[0, 1]
    dxy = (n[2, 2] - n[2, 0] - n[0, 2] + n[0, 0]) / 4.0
    det = dxx * dyy - dxy * dxy
    if det <= 0 or dxx >= 0:  # not a maximum: keep the whole pixel
        return 0.0, 0.0
    sx = -(dyy * dx - dxy * dy) / det
    sy = -(dxx * dy - dxy * dx) / det
    return float(np.clip(sx, -0.5, 0.5)), float(np.clip(sy, -0.5, 0.5))


def _refined(
    patch: np.ndarray, region: np.ndarray, x: int, y: int, ncc: np.ndarray
) -> tuple[float, float, float]:
    """The sub-pixel peak near whole pixel (x, y) of ``ncc`` (the NCC of ``patch`` over
    ``region``) and its NCC: the quadratic's peak, then the region resampled (Lanczos) so
    that the peak falls on a whole pixel and the quadratic fitted again, until the step
    is below 0.005 px.  One quadratic fit is biased towards the whole pixel where the
    texture has energy near the Nyquist limit (its peak is sharp); at the peak
    resampled onto a whole pixel the fit is symmetric, so the bias vanishes."""
    sx, sy = _subpixel(ncc, x, y)
    score = float(ncc[y, x])
    side = patch.shape[0] + 2
    for _ in range(4):
        # The region's pixels around the patch's top-left at (x + sx, y + sy), one more
        # on each side: a 3 x 3 NCC map centred on the estimate.
        cols = np.arange(side, dtype=np.float32) + np.float32(x - 1 + sx)
        rows = np.arange(side, dtype=np.float32) + np.float32(y - 1 + sy)
        map_x, map_y = np.meshgrid(cols, rows)
        moved = cv2.remap(region, map_x, map_y, cv2.INTER_LANCZOS4, borderMode=cv2.BORDER_REFLECT)
        local = cv2.matchTemplate(moved, patch, cv2.TM_CCOEFF_NORMED)
        dx, dy = _subpixel(local, 1, 1)
        sx, sy, score = sx + dx, sy + dy, float(local[1, 1])
        if abs(sx) > 1.0 or abs(sy) > 1.0:  # ran off: keep the whole pixel's fit
            return (*_subpixel(ncc, x, y), float(ncc[y, x]))
        if math.hypot(dx, dy) < 0.005:
            break
    return sx, sy, score


def _quadrant_scores(template: np.ndarray, seen: np.ndarray, min_std_grey: float) -> list[float]:
    """The NCC of each quadrant of the template against the same quadrant of ``seen``,
    for the quadrants with texture of their own (std at least ``min_std_grey``: a plain
    quadrant's NCC is the noise's, near 0 whether hidden or not)."""
    h = template.shape[0] // 2
    scores = []
    for rows in (slice(0, h + 1), slice(h, None)):
        for cols in (slice(0, h + 1), slice(h, None)):
            a = template[rows, cols] - template[rows, cols].mean()
            if float(a.std()) < min_std_grey:
                continue
            b = seen[rows, cols] - seen[rows, cols].mean()
            denom = math.sqrt(float((a * a).sum()) * float((b * b).sum()))
            scores.append(float((a * b).sum()) / denom if denom > 0 else 0.0)
    return scores


def find(
    template: Template,
    image: np.ndarray,
    band: Band,
    config: MatchConfig,
    origin_px: tuple[int, int] = (0, 0),
) -> Match:
    """``template``'s reference point in ``image``, looked for only where ``band``
    allows (band and result in full-frame pixels: ``image``'s plus ``origin_px``, the
    image's top-left in the full frame, for a rendered window).

    The NCC map is computed over the band's rectangle grown by the template; its best
    and second-best local maxima are picked inside the band; the best is refined by a
    quadratic fit.  A best peak on the map's rim (the target may lie beyond) is LOST.
    """
    ox, oy = origin_px
    h = template.half_px
    du, dv = template.offset_px
    height, width = image.shape[:2]
    # Reference-point candidates, in the image's pixels: the band, one more pixel each
    # side for the quadratic fit.
    rect = band.rect((width + ox, height + oy))
    empty = Match(MatchStatus.LOST, None, 0.0, 0.0, template.sigma_px)
    if rect is None:
        return empty
    x0 = max(rect[0] - ox - 1 - h, 0)
    y0 = max(rect[1] - oy - 1 - h, 0)
    x1 = min(rect[2] - ox + 1 + h, width)
    y1 = min(rect[3] - oy + 1 + h, height)
    region = grey_float(image[y0:y1, x0:x1])  # only the searched pixels are converted
    if region.shape[0] < 2 * h + 3 or region.shape[1] < 2 * h + 3:
        return empty
    ncc = cv2.matchTemplate(region, template.patch, cv2.TM_CCOEFF_NORMED)
    # ncc[y, x]: the patch's top-left at (x0 + x, y0 + y); its reference point at
    # (x0 + x + h + du, y0 + y + h + dv) in the image.
    ys, xs = np.mgrid[0 : ncc.shape[0], 0 : ncc.shape[1]]
    u_full = xs + x0 + h + du + ox
    v_full = ys + y0 + h + dv + oy
    inside = band.distance_px(u_full, v_full) <= band.tolerance_px + 0.5
    if not inside.any():
        return empty
    scores = np.where(inside, ncc, -2.0).astype(np.float32)
    y, x = np.unravel_index(int(np.argmax(scores)), scores.shape)
    best = float(ncc[y, x])
    local_max = (scores >= cv2.dilate(scores, np.ones((3, 3), np.uint8))) & inside
    far = np.hypot(xs - x, ys - y) > config.suppression_px
    others = scores[local_max & far]
    second = float(others.max()) if others.size else 0.0
    ambiguity = max(second, 0.0) / best if best > 0 else 1.0
    rim = x in (0, ncc.shape[1] - 1) or y in (0, ncc.shape[0] - 1)
    if not rim:
        sx, sy, refined = _refined(template.patch, region, int(x), int(y), ncc)
        best = max(best, refined)
    else:
        sx, sy = 0.0, 0.0
    uv = (float(u_full[y, x] + sx), float(v_full[y, x] + sy))
    seen = region[y : y + 2 * h + 1, x : x + 2 * h + 1]
    quadrants = _quadrant_scores(template.patch, seen, 3.0 * config.noise_grey)
    split = (
        len(quadrants) > 1
        and max(quadrants) >= config.min_score
        and min(quadrants) < config.occluded_quadrant
    )
    if template.sigma_px > config.max_sigma_px:
        status = MatchStatus.LOW_TEXTURE
    elif rim:
        status = MatchStatus.LOST
    elif split:
        status = MatchStatus.OCCLUDED
    elif best < config.min_score:
        status = MatchStatus.LOST
    elif ambiguity > config.max_ambiguity:
        status = MatchStatus.AMBIGUOUS
    else:
        status = MatchStatus.OK
    return Match(status, uv, best, ambiguity, template.sigma_px)


# -- tracking with drift control -----------------------------------------------------
class Tracker:
    """The dominant eye's fovea, tracked with drift control: the template cut at the
    start is the reference, and a match is the original's wherever that is OK.  A copy
    refreshed at the original's own match (score at least ``refresh_score``), never at
    its own, finds the point when the original no longer does (the view changed): the
    refreshed copy is anchored to the original, so errors do not accumulate."""

    def __init__(
        self, template: Template, config: MatchConfig, refresh_score: float = 0.95
    ) -> None:
        self.original = template
        self.current = template
        self.config = config
        self.refresh_score = refresh_score
        self.refreshes = 0

    def track(self, image: np.ndarray, band: Band, origin_px: tuple[int, int] = (0, 0)) -> Match:
        """The tracked point in ``image`` (band, result and ``origin_px`` as in :func:`find`)."""
        match = find(self.original, image, band, self.config, origin_px)
        if match.ok and match.uv is not None:
            if match.score >= self.refresh_score:
                try:
                    self.current = cut_template(image, match.uv, self.config, origin_px)
                except ValueError:  # too near the image's edge: keep the last copy
                    return match
                self.refreshes += 1
            return match
        if self.current is self.original:
            return match
        return find(self.current, image, band, self.config, origin_px)


__all__ = [
    "Band",
    "Match",
    "MatchConfig",
    "MatchStatus",
    "Rect",
    "Template",
    "Tracker",
    "around",
    "cut_template",
    "epipolar_band",
    "find",
    "grey_float",
    "predicted_sigma_px",
    "row_band",
]
