"""Lens optics applied around MuJoCo's pinhole render: radial distortion and noise.

MuJoCo renders an ideal pinhole image.  A distorted camera is rendered on a
larger pinhole *canvas* with the same focal lengths, then resampled with
``cv2.remap`` so that output pixel (u, v) shows the scene point whose distorted
projection is (u, v).  Radial model (OpenCV, k1, k2 only) on normalised
coordinates: x_d = x (1 + k1 r^2 + k2 r^4).  Pixels as in OpenCV (centres at
integer coordinates).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import cv2
import numpy as np

from headsim.sim.settings import CameraSettings


def centre_ray_yaw(camera: CameraSettings) -> float:
    """Horizontal angle of the image centre's ray off the optical axis, rad.

    Positive towards the camera's +x.  This is what the servo adds to the eye's
    mount yaw when it centres a target on the image centre instead of the
    principal point (exact also with distortion: measured at the centre row).
    """
    u, v = camera.image_centre
    return float(camera.pinhole().column_angle(u, v))


def camera_matrix(camera: CameraSettings) -> np.ndarray:
    """The 3 x 3 intrinsic matrix K of the output image, px."""
    return camera.pinhole().K


def dist_coeffs(camera: CameraSettings) -> np.ndarray:
    """OpenCV distortion vector (k1, k2, p1, p2, k3)."""
    return camera.pinhole().dist_coeffs


def project_points(points_cam: np.ndarray, camera: CameraSettings) -> np.ndarray:
    """Pixels (N, 2) of points (N, 3) in the OpenCV camera frame, m, with distortion.

    NaN for points the camera does not image: behind it, or beyond the fold
    radius of its lens.
    """
    return camera.pinhole().project(np.atleast_2d(np.asarray(points_cam, dtype=float)))


def undistort_pixels(uv: np.ndarray, camera: CameraSettings) -> np.ndarray:
    """Where the ideal pinhole would image the rays of distorted pixels (N, 2), px (NaN: no ray)."""
    return camera.pinhole().undistort(np.atleast_2d(np.asarray(uv, dtype=float)), strict=False)


@dataclass(frozen=True)
class DistortionCanvas:
    """How to render a distorted camera: the pinhole canvas and the resampling map.

    The canvas has the camera's focal lengths, ``size`` = (width, height) px and
    principal point ``principal`` px; ``map_x``/``map_y`` (H, W float32) give,
    for every output pixel, its source on the canvas (-1 where none exists).
    """

    size: tuple[int, int]
    principal: tuple[float, float]
    map_x: np.ndarray | None
    map_y: np.ndarray | None
    valid_fraction: float

    @property
    def identity(self) -> bool:
        """True for a distortion-free camera: the canvas is the image."""
        return self.map_x is None


@functools.lru_cache(maxsize=16)
def distortion_canvas(
    camera: CameraSettings, max_side: int, margin_px: int = 3
) -> DistortionCanvas:
    """Canvas and remap tables for rendering ``camera`` (computed once per camera and process;
    the tables are shared: read-only)."""
    w, h = camera.width, camera.height
    cx, cy = camera.principal
    if not camera.pinhole().is_distorted:
        return DistortionCanvas((w, h), (cx, cy), None, None, 1.0)
    us, vs = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    xy = camera.pinhole().normalise(np.stack([us, vs], axis=-1), strict=False, tol_px=1e-6)
    valid = np.isfinite(xy).all(axis=-1)
    up = camera.kx * xy[..., 0] + cx
    vp = camera.ky * xy[..., 1] + cy
    # Canvas bounds: everything the valid output pixels need, plus a margin for
    # bilinear sampling, at most max_side on a side.
    u_lo = math.floor(float(up[valid].min())) - margin_px
    u_hi = math.ceil(float(up[valid].max())) + margin_px
    v_lo = math.floor(float(vp[valid].min())) - margin_px
    v_hi = math.ceil(float(vp[valid].max())) + margin_px
    u_lo, u_hi = _clamp_span(u_lo, u_hi, max_side)
    v_lo, v_hi = _clamp_span(v_lo, v_hi, max_side)
    map_x = up - u_lo
    map_y = vp - v_lo
    width_c, height_c = u_hi - u_lo + 1, v_hi - v_lo + 1
    inside = (map_x >= 0) & (map_x <= width_c - 1) & (map_y >= 0) & (map_y <= height_c - 1)
    valid &= inside
    map_x[~valid] = -1.0
    map_y[~valid] = -1.0
    map_x, map_y = map_x.astype(np.float32), map_y.astype(np.float32)
    map_x.flags.writeable = map_y.flags.writeable = False  # shared through the cache
    return DistortionCanvas(
        size=(width_c, height_c),
        principal=(cx - u_lo, cy - v_lo),
        map_x=map_x,
        map_y=map_y,
        valid_fraction=float(valid.mean()),
    )


def _clamp_span(lo: int, hi: int, max_side: int) -> tuple[int, int]:
    if hi - lo + 1 <= max_side:
        return lo, hi
    centre = (lo + hi) // 2
    return centre - max_side // 2, centre - max_side // 2 + max_side - 1


def apply_canvas(canvas_rgb: np.ndarray, canvas: DistortionCanvas) -> np.ndarray:
    """Resample a rendered canvas into the distorted output image (black where no source)."""
    if canvas.map_x is None or canvas.map_y is None:
        return canvas_rgb
    return cv2.remap(
        canvas_rgb,
        canvas.map_x,
        canvas.map_y,
        interpolation=cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_CONSTANT,
        borderValue=(0, 0, 0),
    )


#: Random bits per noise value: one byte picks an alias bucket, one decides within it,
#: so every outcome's probability is exact to 2**-16.
_BUCKETS = 256
#: Outcomes whose rounded-Gaussian probability is below this are folded into their neighbours.
_TAIL_PROBABILITY = 2.0**-20


def _rounded_gaussian(std: float) -> tuple[np.ndarray, np.ndarray]:
    """Values k and probabilities P(rint(std * z) = k), z standard normal (tails folded in)."""
    from statistics import NormalDist

    normal = NormalDist()
    k_max = 0
    while 2.0 * (1.0 - normal.cdf((k_max + 0.5) / std)) > _TAIL_PROBABILITY:
        k_max += 1
    values = np.arange(-k_max, k_max + 1)
    edges = [normal.cdf((k + 0.5) / std) for k in range(-k_max - 1, k_max + 1)]
    edges[0], edges[-1] = 0.0, 1.0  # the folded tails
    return values, np.diff(np.array(edges))


@dataclass(frozen=True)
class GaussianNoise:
    """Zero-mean Gaussian image noise of ``std`` grey levels, at about 1 ms per 640x480 frame.

    Adding ``std * z`` and rounding to 8 bits gives an integer offset whose law
    is the rounded Gaussian P(k) = Phi((k + 1/2)/std) - Phi((k - 1/2)/std) (the
    image is integer).  That law is sampled directly with Walker's alias
    method: two random bytes per value, two 8-bit table look-ups and a
    comparison, all in OpenCV; the result is the image plus the offset,
    saturated to [0, 255] in one pass
    (what ``clip(rint(image + std * z))`` gives).  Probabilities are exact to
    2**-16 (each); the outcomes too rare for that (beyond about 4 std, a tail
    of less than 1e-4) are folded into the extreme values.  Noise of image number ``frame`` of a stream ``key`` is
    drawn from its own generator, seeded by ``(*key, frame)``: the same for a
    given seed, camera and image count, and independent between images,
    pixels and colour channels.  Up to 127 outcomes on each side (std <= 25);
    larger noise falls back to float samples with the same law.
    """

    std: float
    #: (alias, threshold) per bucket and k_max; None: float samples (std > 25 or no noise).
    tables: tuple[np.ndarray, np.ndarray, int] | None

    @classmethod
    def of(cls, std: float) -> GaussianNoise:
        """Precompute the alias tables for noise of ``std`` grey levels."""
        if std <= 0:
            return cls(0.0, None)
        values, probs = _rounded_gaussian(std)
        if len(values) > _BUCKETS:
            return cls(float(std), None)
        # Probabilities in whole units of 2**-16 (largest remainders), then
        # Vose's alias method on 256 equally likely buckets of 256 units each.
        exact = probs * 65536.0
        units = np.floor(exact).astype(int)
        short = 65536 - int(units.sum())
        units[np.argsort(units - exact)[:short]] += 1
        weight = np.zeros(_BUCKETS, dtype=int)
        weight[: len(values)] = units
        primary = np.arange(_BUCKETS)
        alias = np.arange(_BUCKETS)
        keep = np.full(_BUCKETS, _BUCKETS)
        small = [i for i in range(_BUCKETS) if weight[i] < _BUCKETS]
        large = [i for i in range(_BUCKETS) if weight[i] >= _BUCKETS]
        while small and large:
            s, g = small.pop(), large.pop()
            keep[s], alias[s] = weight[s], g
            weight[g] -= _BUCKETS - weight[s]
            (small if weight[g] < _BUCKETS else large).append(g)
        # A full bucket (256 of 256) keeps its primary whatever the byte: alias to itself.
        alias = np.where(keep >= _BUCKETS, primary, alias)
        threshold = np.minimum(keep, _BUCKETS - 1)
        return cls(
            float(std), (alias.astype(np.uint8), threshold.astype(np.uint8), len(values) // 2)
        )

    def probabilities(self) -> dict[int, float]:
        """The offset law this sampler draws from: value -> probability (exact fractions of 2**-16)."""
        if self.std <= 0:
            return {0: 1.0}
        values, probs = _rounded_gaussian(self.std)
        if self.tables is None:
            return dict(zip(values.tolist(), probs.tolist(), strict=True))
        alias, threshold, k_max = self.tables
        law: dict[int, float] = {}
        for bucket in range(_BUCKETS):
            p_keep = (threshold[bucket] if alias[bucket] != bucket else _BUCKETS) / _BUCKETS
            for outcome, p in ((bucket, p_keep), (int(alias[bucket]), 1.0 - p_keep)):
                if p > 0:
                    value = outcome - k_max
                    law[value] = law.get(value, 0.0) + p / _BUCKETS
        return law

    def apply(
        self,
        image: np.ndarray,
        key: tuple[int, ...],
        frame: int,
        crop: tuple[int, int, int, int] | None = None,
    ) -> np.ndarray:
        """``image`` (8-bit) plus noise image number ``frame`` of stream ``key``.

        ``crop`` = (x0, y0, full width, full height): ``image`` is the window at
        (x0, y0) of a full frame of that size, and gets that part of the full
        frame's noise.
        """
        if self.std <= 0:
            return image
        height, width = image.shape[:2]
        x0, y0, full_w, full_h = (0, 0, width, height) if crop is None else crop
        channels = image.shape[2] if image.ndim == 3 else 1
        full_shape = (full_h, full_w * channels)
        rows = slice(y0, y0 + height)
        columns = slice(x0 * channels, (x0 + width) * channels)
        bits = np.random.SFC64(np.random.SeedSequence([*key, frame]))
        flat = np.ascontiguousarray(image).reshape(height, width * channels)
        if self.tables is None:
            z = np.random.Generator(bits).standard_normal(size=full_shape, dtype=np.float32)
            noisy = flat.astype(np.float32) + np.float32(self.std) * z[rows, columns]
            return np.clip(np.rint(noisy), 0, 255).astype(np.uint8).reshape(image.shape)
        alias, threshold, k_max = self.tables
        size = full_shape[0] * full_shape[1]
        raw = bits.random_raw((2 * size + 7) // 8).view(np.uint8)
        bucket = raw[:size].reshape(full_shape)[rows, columns]
        within = raw[size : 2 * size].reshape(full_shape)[rows, columns]
        # Outcome index: the bucket itself (Vose's primary) or its alias; offset = index - k_max.
        outcome = cv2.LUT(bucket, alias)
        cv2.copyTo(bucket, cv2.compare(within, cv2.LUT(bucket, threshold), cv2.CMP_LT), outcome)
        # One saturating pass: image + outcome - k_max, exact integers in float, to [0, 255].
        noisy = cv2.addWeighted(flat, 1.0, outcome, 1.0, -float(k_max), dtype=cv2.CV_8U)
        return noisy.reshape(image.shape)


def add_noise(image: np.ndarray, std: float, rng: np.random.Generator) -> np.ndarray:
    """Add zero-mean Gaussian noise of ``std`` grey levels to an 8-bit image.

    The same law as :class:`GaussianNoise`, seeded from ``rng``; for many
    images of one camera use :class:`GaussianNoise` (tables built once).
    """
    seed = int(rng.integers(0, 2**63))
    return GaussianNoise.of(std).apply(image, (seed,), 0)
