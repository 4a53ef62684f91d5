"""Lens optics applied around MuJoCo's pinhole render: radial distortion and noise.

MuJoCo renders an ideal pinhole image.  A distorted camera is rendered on a
larger pinhole *canvas* with the same focal lengths, then resampled with
``cv2.remap`` so that output pixel (u, v) shows the scene point whose distorted
projection is (u, v).  Radial model (OpenCV, k1, k2 only) on normalised
coordinates: x_d = x (1 + k1 r^2 + k2 r^4).  Pixels as in OpenCV (centres at
integer coordinates).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from headsim.settings import CameraSettings


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


def distortion_canvas(
    camera: CameraSettings, max_side: int, margin_px: int = 3
) -> DistortionCanvas:
    """Canvas and remap tables for rendering ``camera`` (computed once per camera)."""
    w, h = camera.width, camera.height
    cx, cy = camera.principal
    if not camera.distorted:
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
    return DistortionCanvas(
        size=(width_c, height_c),
        principal=(cx - u_lo, cy - v_lo),
        map_x=map_x.astype(np.float32),
        map_y=map_y.astype(np.float32),
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


def add_noise(image: np.ndarray, std: float, rng: np.random.Generator) -> np.ndarray:
    """Add zero-mean Gaussian noise of ``std`` grey levels to an 8-bit image."""
    if std <= 0:
        return image
    noise = rng.standard_normal(size=image.shape, dtype=np.float32)
    noisy = image.astype(np.float32) + np.float32(std) * noise
    return np.clip(np.rint(noisy), 0, 255).astype(np.uint8)
