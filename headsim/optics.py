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

#: Newton iterations for the radial inverse; converges in < 10 for real lenses.
_NEWTON_ITERATIONS = 50
_INVERSE_TOLERANCE = 1e-13


def distort_normalized(xy: np.ndarray, k1: float, k2: float) -> np.ndarray:
    """Apply radial distortion to normalised points (..., 2) -> (..., 2)."""
    xy = np.asarray(xy, dtype=float)
    r2 = np.sum(xy * xy, axis=-1, keepdims=True)
    return xy * (1.0 + k1 * r2 + k2 * r2 * r2)


def undistort_normalized(xy_d: np.ndarray, k1: float, k2: float) -> tuple[np.ndarray, np.ndarray]:
    """Invert radial distortion on normalised points (..., 2).

    Returns ``(xy, valid)``: the undistorted points and a mask that is False
    where no undistorted point on the lens's monotonic branch maps there (the
    distortion folds over before that radius).
    """
    xy_d = np.asarray(xy_d, dtype=float)
    rd = np.sqrt(np.sum(xy_d * xy_d, axis=-1))
    if k1 == 0.0 and k2 == 0.0:
        return xy_d.copy(), np.ones(rd.shape, dtype=bool)
    # Solve rd = r + k1 r^3 + k2 r^5 for r by Newton from r = rd.
    r = rd.copy()
    for _ in range(_NEWTON_ITERATIONS):
        r2 = r * r
        f = r * (1.0 + k1 * r2 + k2 * r2 * r2) - rd
        df = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2
        step = f / np.where(np.abs(df) > 1e-12, df, 1e-12)
        r = np.clip(r - step, 0.0, 10.0)
        if np.all(np.abs(step) < _INVERSE_TOLERANCE):
            break
    r2 = r * r
    residual = np.abs(r * (1.0 + k1 * r2 + k2 * r2 * r2) - rd)
    slope = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2
    # On the monotonic branch every smaller radius also has a positive slope.
    valid = (residual < 1e-9) & (slope > 0) & _monotonic_up_to(r, k1, k2)
    scale = np.where(rd > 0, r / np.where(rd > 0, rd, 1.0), 1.0)
    return xy_d * scale[..., None], valid


def _monotonic_up_to(r: np.ndarray, k1: float, k2: float) -> np.ndarray:
    """True where r(1 + k1 r^2 + k2 r^4) increases on all of [0, r]."""
    # Roots of the slope 1 + 3 k1 s + 5 k2 s^2 in s = r^2 bound the branch.
    if k2 == 0.0:
        s_max = -1.0 / (3.0 * k1) if k1 < 0 else math.inf
    else:
        roots = np.roots([5.0 * k2, 3.0 * k1, 1.0])
        positive = [z.real for z in roots if abs(z.imag) < 1e-12 and z.real > 0]
        s_max = min(positive) if positive else math.inf
    return r * r < s_max


def centre_ray_yaw(camera: CameraSettings) -> float:
    """Horizontal angle of the image centre's ray off the optical axis, rad.

    Positive towards the camera's +x.  This is what the servo adds to the eye's
    mount yaw when it centres a target on the image centre instead of the
    principal point (exact also with distortion: measured at the centre row).
    """
    (u, v), (cx, cy) = camera.image_centre, camera.principal
    xy_d = np.array([(u - cx) / camera.kx, (v - cy) / camera.ky])
    xy, valid = undistort_normalized(xy_d, camera.k1, camera.k2)
    if not bool(valid):
        raise ValueError("the image centre has no undistorted ray: the distortion folds over there")
    return math.atan(float(xy[0]))


def camera_matrix(camera: CameraSettings) -> np.ndarray:
    """The 3 x 3 intrinsic matrix K of the output image, px."""
    cx, cy = camera.principal
    return np.array([[camera.kx, 0.0, cx], [0.0, camera.ky, cy], [0.0, 0.0, 1.0]])


def dist_coeffs(camera: CameraSettings) -> np.ndarray:
    """OpenCV distortion vector (k1, k2, p1, p2, k3)."""
    return np.array([camera.k1, camera.k2, 0.0, 0.0, 0.0])


def project_points(points_cam: np.ndarray, camera: CameraSettings) -> np.ndarray:
    """Project points in the OpenCV camera frame (N, 3), m, to pixels (N, 2) with distortion."""
    p = np.atleast_2d(np.asarray(points_cam, dtype=float))
    if np.any(p[:, 2] <= 0):
        raise ValueError("a point lies behind the camera (z <= 0)")
    xy = distort_normalized(p[:, :2] / p[:, 2:3], camera.k1, camera.k2)
    cx, cy = camera.principal
    return np.column_stack([camera.kx * xy[:, 0] + cx, camera.ky * xy[:, 1] + cy])


def undistort_pixels(uv: np.ndarray, camera: CameraSettings) -> np.ndarray:
    """Map distorted pixels (N, 2) to where the ideal pinhole would image them, px."""
    uv = np.atleast_2d(np.asarray(uv, dtype=float))
    cx, cy = camera.principal
    xy_d = np.column_stack([(uv[:, 0] - cx) / camera.kx, (uv[:, 1] - cy) / camera.ky])
    xy, valid = undistort_normalized(xy_d, camera.k1, camera.k2)
    out = np.column_stack([camera.kx * xy[:, 0] + cx, camera.ky * xy[:, 1] + cy])
    out[~valid] = np.nan
    return out


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
    xy_d = np.stack([(us - cx) / camera.kx, (vs - cy) / camera.ky], axis=-1)
    xy, valid = undistort_normalized(xy_d, camera.k1, camera.k2)
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
