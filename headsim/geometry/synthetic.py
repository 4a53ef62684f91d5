"""Exact forward model of the head: what it observes of a known point, no simulator.

Frames and signs as in docs/equations.md: points in H (x right from C1 to C2, y down,
z forward, origin mid-baseline), m; eye angles are encoder readings, rad,
positive inwards; the true yaw of camera i is ``eye_angle + alpha_ei``.

Model 2 (Sec. II-C): step 1 turns the eyes until P's image in Ca1 lies at column
``u10`` (eye angle ``alpha1``), step 2 until P's image in Ca2 lies at ``u20``
(``alpha2``).  Model 1's servo (the neck too) is :mod:`headsim.geometry.synthetic_neck`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from headsim.geometry._roots import solve_increasing
from headsim.geometry.camera_model import PinholeCamera, ideal
from headsim.geometry.kinematics import ENCODER_RESOLUTION, head_to_camera

__all__ = [
    "ENCODER_RESOLUTION",
    "Fixation",
    "Observation",
    "StereoHead",
    "effective_initial_direction",
    "fixation_angles",
    "image_points",
    "mount_yaw_for_direction",
    "observe",
    "quantise",
]


@dataclass(frozen=True)
class StereoHead:
    """The eyes: baseline D, m; intrinsics; mount offsets alpha_ei, rad; servo target columns, px.

    ``u10``/``u20`` default to each image's centre column.  ``nodal1``/``nodal2``
    and ``side1``/``side2``, m: each optical centre's offset from its eye's yaw
    axis, forward along the optical axis and along the camera's x
    (docs/equations.md, last section); 0 is the paper's eye.
    """

    baseline: float
    cam1: PinholeCamera = field(default_factory=ideal)
    cam2: PinholeCamera = field(default_factory=ideal)
    alpha_e1: float = 0.0
    alpha_e2: float = 0.0
    u10: float | None = None
    u20: float | None = None
    encoder_resolution: float = ENCODER_RESOLUTION
    nodal1: float = 0.0
    nodal2: float = 0.0
    side1: float = 0.0
    side2: float = 0.0

    def __post_init__(self) -> None:
        for name in ("nodal1", "nodal2", "side1", "side2"):
            if not abs(getattr(self, name)) < 0.25 * self.baseline + 0.1:
                raise ValueError(f"{name} must be an offset in metres, got {getattr(self, name)!r}")
        if not (math.isfinite(self.baseline) and 0.0 < self.baseline < 10.0):
            raise ValueError(f"baseline must be in metres, 0 < D < 10, got {self.baseline!r}")
        for name in ("alpha_e1", "alpha_e2"):
            if not abs(getattr(self, name)) < math.pi / 2:
                raise ValueError(
                    f"{name} must be a yaw in radians, |.| < pi/2, got {getattr(self, name)!r}"
                )
        if not self.encoder_resolution > 0.0:
            raise ValueError(f"encoder_resolution must be > 0 rad, got {self.encoder_resolution!r}")

    @property
    def target_columns(self) -> tuple[float, float]:
        """The servo's target columns (u10, u20), px."""
        return (
            self.cam1.image_centre[0] if self.u10 is None else self.u10,
            self.cam2.image_centre[0] if self.u20 is None else self.u20,
        )

    def camera(self, camera: int) -> PinholeCamera:
        """Intrinsics of camera 1 or 2."""
        if camera not in (1, 2):
            raise ValueError(f"camera must be 1 or 2, got {camera!r}")
        return self.cam1 if camera == 1 else self.cam2

    def offsets(self, camera: int) -> tuple[float, float]:
        """(nodal, side) offsets of camera 1 or 2's optical centre, m."""
        self.camera(camera)
        return (self.nodal1, self.side1) if camera == 1 else (self.nodal2, self.side2)

    def line_of_sight_offsets(self, v: float | None = None) -> tuple[float, float]:
        """(s1, s2): how far each target column's line of sight misses its yaw axis, m.

        ``s_i = e_i cos t_i - n_i sin t_i`` along the effective camera's x, t_i the
        column's horizontal angle off the optical axis (at row ``v``, default each
        image's centre row; exact for points on that row, or without distortion).
        """
        out = []
        for camera, u0 in zip((1, 2), self.target_columns, strict=True):
            nodal, side = self.offsets(camera)
            t = float(self.camera(camera).column_angle(u0, v))
            out.append(side * math.cos(t) - nodal * math.sin(t))
        return (out[0], out[1])

    def effective_initial_directions(self, v: float | None = None) -> tuple[float, float]:
        """(alpha_e1, alpha_e2) as Model 2 sees them when fixating at the target columns, rad.

        See :func:`effective_initial_direction`; ``v`` is the row, default each image's centre row.
        """
        u10, u20 = self.target_columns
        return (
            effective_initial_direction(1, self.alpha_e1, self.cam1, u10, v),
            effective_initial_direction(2, self.alpha_e2, self.cam2, u20, v),
        )


def effective_initial_direction(
    camera: int, alpha_e: float, cam: PinholeCamera, u0: float, v: float | None = None
) -> float:
    """Initial direction of eye ``camera`` as seen by a servo that fixates at column ``u0``, rad.

    ``alpha_e1 + atan(x_n)`` for Ca1 and ``alpha_e2 - atan(x_n)`` for Ca2, where
    ``x_n`` is the undistorted normalised x of pixel ``(u0, v)`` (``v`` defaults
    to the image centre row); without distortion ``x_n = (u0 - cx) / kx``.
    Exact for points imaged on row ``v``.
    """
    angle = float(cam.column_angle(u0, v))
    if camera == 1:
        return alpha_e + angle
    if camera == 2:
        return alpha_e - angle
    raise ValueError(f"camera must be 1 or 2, got {camera!r}")


def mount_yaw_for_direction(
    camera: int,
    effective: float,
    cam: PinholeCamera,
    u0: float | None = None,
    v: float | None = None,
) -> float:
    """The mount offset alpha_e, rad, whose :func:`effective_initial_direction` is ``effective``.

    Its inverse: ``effective - atan(x_n)`` for Ca1, ``effective + atan(x_n)`` for
    Ca2, at column ``u0`` (default the image centre's) and row ``v`` (default
    the image centre row).
    """
    angle = float(cam.column_angle(cam.image_centre[0] if u0 is None else u0, v))
    if camera == 1:
        return effective - angle
    if camera == 2:
        return effective + angle
    raise ValueError(f"camera must be 1 or 2, got {camera!r}")


def quantise(angle: ArrayLike, resolution: float = ENCODER_RESOLUTION) -> np.ndarray:
    """Round angles, rad, to the nearest whole encoder step of ``resolution`` rad."""
    if not resolution > 0.0:
        raise ValueError(f"resolution must be > 0 rad, got {resolution!r}")
    return np.round(np.asarray(angle, dtype=float) / resolution) * resolution


def image_points(
    head: StereoHead, points_h: ArrayLike, camera: int, eye_angle: ArrayLike
) -> np.ndarray:
    """Pixels (N, 2) of points (N, 3) in H seen by camera 1 or 2 at the given eye angle(s), rad.

    NaN where the point is not imaged (behind the camera, or beyond the lens's fold).
    """
    p = _points_h(points_h)
    offset = head.alpha_e1 if camera == 1 else head.alpha_e2
    yaw = np.asarray(eye_angle, dtype=float) + offset
    nodal, side = head.offsets(camera)
    return head.camera(camera).project(
        head_to_camera(p, camera, yaw, head.baseline, nodal=nodal, side=side)
    )


@dataclass(frozen=True)
class Fixation:
    """Eye angles of Model 2's two steps for N points, rad, and where they exist.

    alpha1: (N,) eye angle putting P at column u10 in Ca1; alpha2: (N,) at u20 in
    Ca2.  ``valid`` (N,) is False (angles NaN) where the point cannot be fixated:
    not finite, not in front of the baseline (z_h <= 0), a camera would have to
    turn to +-pi/2 or beyond, or P would image beyond the lens's fold.
    """

    alpha1: np.ndarray
    alpha2: np.ndarray
    valid: np.ndarray


def fixation_angles(head: StereoHead, points_h: ArrayLike) -> Fixation:
    """Exact fixation eye angles of points (N, 3) in H.

    Closed form for a distortion-free camera; with distortion a safeguarded
    Newton solve of the column equation in the camera's horizontal angle, on
    the lens's monotonic branch.  With the optical centre off the yaw axis the
    column's line of sight misses the axis by ``s = e cos t - n sin t``: the
    ray's direction is ``phi -+ asin(s / R)`` (R: P's horizontal distance from
    the axis); with distortion t and the range along the ray are iterated to a
    fixed point.
    """
    p = _points_h(points_h)
    u10, u20 = head.target_columns
    half = head.baseline / 2.0
    phi1 = np.arctan2(p[:, 0] + half, p[:, 2])
    phi2 = np.arctan2(p[:, 0] - half, p[:, 2])
    r1 = np.hypot(p[:, 0] + half, p[:, 2])
    r2 = np.hypot(p[:, 0] - half, p[:, 2])
    t1, b1 = _offset_ray(head, 1, u10, p, r1)
    t2, b2 = _offset_ray(head, 2, u20, p, r2)
    with np.errstate(invalid="ignore"):
        yaw1 = phi1 - b1 - t1  # Ca1 sees P at angle phi1 - yaw1 (on its axis)
        yaw2 = t2 + b2 - phi2  # Ca2 sees P at angle phi2 + yaw2
    valid = (
        np.isfinite(yaw1)
        & np.isfinite(yaw2)
        & (p[:, 2] > 0.0)
        & (np.abs(yaw1) < math.pi / 2)
        & (np.abs(yaw2) < math.pi / 2)
    )
    nan = np.full_like(yaw1, np.nan)
    return Fixation(
        alpha1=np.where(valid, yaw1 - head.alpha_e1, nan),
        alpha2=np.where(valid, yaw2 - head.alpha_e2, nan),
        valid=valid,
    )


def _offset_ray(
    head: StereoHead, camera: int, u0: float, p: np.ndarray, r: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Column angle t (N,) and the angle asin(s / R) (N,) by which the ray misses the axis, rad."""
    nodal, side = head.offsets(camera)
    cam = head.camera(camera)
    rho = r
    t = _column_ray_angle(cam, u0, p[:, 1] / rho)
    if nodal == 0.0 and side == 0.0:
        return t, np.zeros_like(t)
    for _ in range(1 if not cam.is_distorted else 8):  # bounded fixed point; 8 reach 1e-16
        s = side * np.cos(t) - nodal * np.sin(t)
        with np.errstate(invalid="ignore"):
            # P's horizontal range from the optical centre along the ray.
            rho = np.sqrt(r * r - s * s) - (side * np.sin(t) + nodal * np.cos(t))
        if cam.is_distorted:
            t = _column_ray_angle(cam, u0, p[:, 1] / rho)
    s = side * np.cos(t) - nodal * np.sin(t)
    with np.errstate(invalid="ignore"):
        return t, np.arcsin(s / r)


def _column_ray_angle(cam: PinholeCamera, u0: float, eta: np.ndarray) -> np.ndarray:
    """Horizontal angle t in the camera at which P images at column u0, (N,), rad.

    eta: (N,) P's y over its horizontal range from the optical centre (y_n cos t).
    """
    target = (u0 - cam.cx) / cam.kx  # distorted normalised x at the target column
    if not cam.is_distorted:
        return np.full(eta.shape[0], math.atan(target))
    k1, k2 = cam.k1, cam.k2

    def column(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        xn = np.tan(t)
        yn = eta / np.cos(t)
        r2 = xn * xn + yn * yn
        s = 1.0 + k1 * r2 + k2 * r2 * r2
        ds = k1 + 2.0 * k2 * r2
        return xn * s - target, (1.0 + xn * xn) * s + 2.0 * xn * xn * ds * (1.0 + r2)

    # Stay where the radius is inside the fold: sin^2 t (1 + rf^2) <= rf^2 - eta^2.
    rf2 = min(cam.fold_radius, 1e3) ** 2
    with np.errstate(invalid="ignore"):
        t_max = np.arcsin(np.sqrt((rf2 - eta * eta) / (1.0 + rf2))) * (1.0 - 1e-12)
    t, _ = solve_increasing(column, -t_max, t_max, np.full_like(eta, math.atan(target)), 1e-15)
    return t


@dataclass(frozen=True)
class Observation:
    """What the head records for N points in Model 2's two steps.

    alpha1, alpha2: (N,) eye angles of steps 1 and 2, rad (exact or quantised).
    gamma1, gamma2: (N,) eye angles at which ``uv1``, ``uv2`` were taken, rad.
    uv1: (N, 2) P's image in Ca1 at gamma1 (the paper's (u11, v11): gamma1 = alpha2), px.
    uv2: (N, 2) P's image in Ca2 at gamma2 (the paper's (u21, v21): gamma2 = alpha1), px.
    valid: (N,) False where the point cannot be fixated or an image point is missing.
    in_view: (N,) whether both y images also fall on the sensors (the model itself
    has no image border; a real head needs this too).
    """

    alpha1: np.ndarray
    alpha2: np.ndarray
    gamma1: np.ndarray
    gamma2: np.ndarray
    uv1: np.ndarray
    uv2: np.ndarray
    valid: np.ndarray
    in_view: np.ndarray


def observe(
    head: StereoHead,
    points_h: ArrayLike,
    *,
    quantised: bool = False,
    gamma1: ArrayLike | None = None,
    gamma2: ArrayLike | None = None,
) -> Observation:
    """Model 2's measurement of points (N, 3) in H.

    With ``quantised`` the eye angles (and given gammas) are rounded to the
    encoder and the images are those seen at the rounded angles, so P is only
    near its target column.  ``gamma1``/``gamma2`` (scalar or (N,), rad) choose
    the eye angles of the y images (default alpha2 and alpha1; 0 is the paper's
    near-midline remedy).
    """
    p = _points_h(points_h)
    fix = fixation_angles(head, p)
    alpha1, alpha2 = fix.alpha1, fix.alpha2
    n = p.shape[0]
    g1 = alpha2 if gamma1 is None else np.broadcast_to(np.asarray(gamma1, float), (n,))
    g2 = alpha1 if gamma2 is None else np.broadcast_to(np.asarray(gamma2, float), (n,))
    if quantised:
        res = head.encoder_resolution
        alpha1, alpha2 = quantise(alpha1, res), quantise(alpha2, res)
        g1 = alpha2 if gamma1 is None else quantise(g1, res)
        g2 = alpha1 if gamma2 is None else quantise(g2, res)
    uv1 = image_points(head, p, 1, g1)
    uv2 = image_points(head, p, 2, g2)
    valid = fix.valid & np.isfinite(uv1).all(axis=1) & np.isfinite(uv2).all(axis=1)
    in_view = valid & head.cam1.contains(uv1) & head.cam2.contains(uv2)
    return Observation(
        alpha1, alpha2, np.asarray(g1, float), np.asarray(g2, float), uv1, uv2, valid, in_view
    )


def _points_h(points_h: ArrayLike) -> np.ndarray:
    p = np.asarray(points_h, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points_h must have shape (N, 3), got {p.shape}")
    return p
