"""Pinhole camera with OpenCV's radial distortion (k1, k2), vectorised.

Camera frame: OpenCV (x right, y down, z along the optical axis), metres.
Pixels: OpenCV convention, pixel centres at integer coordinates, so the image
centre of a W x H image is ((W-1)/2, (H-1)/2).  Normalised coordinates are
``x_n = x_c / z_c``, ``y_n = y_c / z_c``; the lens maps them to
``x_d = x_n (1 + k1 r^2 + k2 r^4)`` and ``u = kx x_d + cx``, ``v = ky y_d + cy``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from headsim.geometry._roots import solve_increasing
from headsim.paper import IMAGE_SIZE_PX, INTRINSICS

__all__ = [
    "PinholeCamera",
    "UndistortionError",
    "ideal",
    "image_centre",
    "paper_cam1",
    "paper_cam2",
]


class UndistortionError(ValueError):
    """Some pixels have no undistorted ray on the lens's monotonic branch."""


@dataclass(frozen=True)
class PinholeCamera:
    """Intrinsics of one camera: image size, px; kx, ky, px per unit normalised; (cx, cy), px."""

    width: int
    height: int
    kx: float
    ky: float
    cx: float
    cy: float
    k1: float = 0.0
    k2: float = 0.0

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if not (isinstance(value, int | np.integer) and value > 0):
                raise ValueError(
                    f"{name} must be a positive integer number of pixels, got {value!r}"
                )
        for name in ("kx", "ky"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive focal length in pixels, got {value!r}")
        for name in ("cx", "cy", "k1", "k2"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"{name} must be finite, got {getattr(self, name)!r}")

    @property
    def K(self) -> np.ndarray:
        """Intrinsic matrix (3, 3), px."""
        return np.array([[self.kx, 0.0, self.cx], [0.0, self.ky, self.cy], [0.0, 0.0, 1.0]])

    @property
    def dist_coeffs(self) -> np.ndarray:
        """OpenCV distortion vector (k1, k2, p1, p2, k3), (5,)."""
        return np.array([self.k1, self.k2, 0.0, 0.0, 0.0])

    @property
    def image_centre(self) -> tuple[float, float]:
        """Geometric centre of the image ((W-1)/2, (H-1)/2), px."""
        return image_centre(self.width, self.height)

    @property
    def is_distorted(self) -> bool:
        """True when k1 or k2 is non-zero."""
        return self.k1 != 0.0 or self.k2 != 0.0

    @functools.cached_property  # a root of a polynomial, asked for at every projection
    def fold_radius(self) -> float:
        """Normalised radius where ``r (1 + k1 r^2 + k2 r^4)`` stops increasing (inf if never)."""
        # Slope 1 + 3 k1 s + 5 k2 s^2 in s = r^2: its smallest positive root.
        roots: np.ndarray | list[complex] = (
            np.roots([5.0 * self.k2, 3.0 * self.k1, 1.0]) if self.is_distorted else []
        )
        positive = [z.real for z in roots if abs(z.imag) < 1e-12 and z.real > 0.0]
        return math.sqrt(min(positive)) if positive else math.inf

    def contains(self, uv: ArrayLike) -> np.ndarray:
        """Whether pixels (..., 2) lie on the sensor, [-0.5, W - 0.5] x [-0.5, H - 0.5]."""
        uv = _pairs(uv, "uv")
        u, v = uv[..., 0], uv[..., 1]
        return (u >= -0.5) & (u <= self.width - 0.5) & (v >= -0.5) & (v <= self.height - 0.5)

    def distort_normalised(self, xy: ArrayLike) -> np.ndarray:
        """Apply the radial model to normalised points (..., 2) -> (..., 2)."""
        xy = _pairs(xy, "xy")
        r2 = np.sum(xy * xy, axis=-1, keepdims=True)
        return xy * (1.0 + self.k1 * r2 + self.k2 * r2 * r2)

    def project(self, points_c: ArrayLike) -> np.ndarray:
        """Pixels (..., 2) of points (..., 3) in this camera's frame, m.

        NaN marks points that are not imaged: at or behind the camera plane
        (z_c <= 0), or beyond the fold radius of the distortion, where the lens
        model stops being one-to-one.
        """
        p = np.asarray(points_c, dtype=float)
        if p.ndim == 0 or p.shape[-1] != 3:
            raise ValueError(f"points_c must have shape (..., 3), got {p.shape}")
        z = p[..., 2:3]
        with np.errstate(divide="ignore", invalid="ignore"):
            xy = p[..., :2] / z
        seen = z[..., 0] > 0.0
        if self.is_distorted:
            seen &= np.sum(xy * xy, axis=-1) < self.fold_radius**2
            xy = self.distort_normalised(xy)
        uv = np.stack([self.kx * xy[..., 0] + self.cx, self.ky * xy[..., 1] + self.cy], axis=-1)
        return np.where(seen[..., None], uv, np.nan)

    def normalise(self, uv: ArrayLike, *, strict: bool = True, tol_px: float = 1e-12) -> np.ndarray:
        """Undistorted normalised coordinates (..., 2) of pixels (..., 2).

        Inverts the radial model by a safeguarded Newton iteration on the radius,
        on the monotonic branch only; a result counts as converged when distorting
        it again reproduces the pixel within ``tol_px``.  Pixels without such a
        ray (beyond the fold, or NaN) raise :class:`UndistortionError` when
        ``strict``, else come back as NaN.
        """
        uv = _pairs(uv, "uv")
        xd = np.stack([(uv[..., 0] - self.cx) / self.kx, (uv[..., 1] - self.cy) / self.ky], -1)
        if not self.is_distorted:
            return xd
        rd = np.hypot(xd[..., 0], xd[..., 1])
        k1, k2 = self.k1, self.k2

        def g(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            s = r * r
            return r * (1.0 + k1 * s + k2 * s * s) - rd, 1.0 + 3.0 * k1 * s + 5.0 * k2 * s * s

        scale_px = max(self.kx, self.ky)
        r_max = min(self.fold_radius, 1e3)
        r, _ = solve_increasing(
            g, np.zeros_like(rd), np.full_like(rd, r_max), rd, 1e-3 * tol_px / scale_px
        )
        residual_px = np.abs(g(r)[0]) * scale_px
        ok = np.isfinite(r) & (residual_px <= tol_px)
        if strict and not ok.all():
            bad = np.flatnonzero(~ok.reshape(-1))
            raise UndistortionError(
                f"{bad.size} of {ok.size} pixels have no undistorted ray within {tol_px} px "
                f"(first at flat index {bad[0]}: uv = {uv.reshape(-1, 2)[bad[0]].tolist()}); "
                f"the lens folds over at normalised radius {self.fold_radius:.4g}"
            )
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(rd > 0.0, r / rd, 1.0)
        return np.where(ok[..., None], xd * ratio[..., None], np.nan)

    def undistort(self, uv: ArrayLike, *, strict: bool = True, tol_px: float = 1e-12) -> np.ndarray:
        """Pixels (..., 2) where this camera without distortion would image the rays of ``uv``."""
        xy = self.normalise(uv, strict=strict, tol_px=tol_px)
        return np.stack([self.kx * xy[..., 0] + self.cx, self.ky * xy[..., 1] + self.cy], axis=-1)

    def column_angle(self, u: ArrayLike, v: ArrayLike | None = None) -> np.ndarray:
        """Horizontal angle atan(x_n) of the ray imaged at pixel (u, v), rad, positive to +x.

        ``v`` defaults to the image centre row.  Without distortion the result
        does not depend on ``v``: ``atan((u - cx) / kx)``.
        """
        u = np.asarray(u, dtype=float)
        v = np.full_like(u, self.image_centre[1]) if v is None else np.asarray(v, dtype=float)
        return np.arctan(self.normalise(np.stack(np.broadcast_arrays(u, v), axis=-1))[..., 0])


def image_centre(width: int, height: int) -> tuple[float, float]:
    """Geometric centre ((W-1)/2, (H-1)/2), px, of a W x H image (pixel centres at integers)."""
    return ((width - 1) / 2.0, (height - 1) / 2.0)


def ideal() -> PinholeCamera:
    """640 x 480, square pixels, fovy 45 deg (f = 240 / tan 22.5 deg = 579.41 px), centred."""
    f = 240.0 / math.tan(math.radians(22.5))
    return PinholeCamera(640, 480, f, f, 319.5, 239.5)


def paper_cam1() -> PinholeCamera:
    """Ca1 of the paper (Zhang calibration, Sec. VI-B; docs/equations.md's last table), k2 = 0."""
    return PinholeCamera(*IMAGE_SIZE_PX, **INTRINSICS[0])


def paper_cam2() -> PinholeCamera:
    """Ca2 of the paper (Zhang calibration, Sec. VI-B; docs/equations.md's last table), k2 = 0."""
    return PinholeCamera(*IMAGE_SIZE_PX, **INTRINSICS[1])


def _pairs(a: ArrayLike, name: str) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if a.ndim == 0 or a.shape[-1] != 2:
        raise ValueError(f"{name} must have shape (..., 2), got {a.shape}")
    return a
