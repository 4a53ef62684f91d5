"""Rigid transforms of the head: the neck's D-H transform, eq. (1), and the eye poses.

Frames (docs/equations.md): W world (z up, y forward, x right), H head (x right from
C1 to C2, y down, z forward, origin mid-baseline), Ci camera i (OpenCV: x right,
y down, z along the optical axis).  Transforms are named ``dst_from_src`` and
act on homogeneous column vectors: ``p_W = world_from_head(...) @ p_H``.
Lengths in metres, angles in radians.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from headsim.geometry.transforms import points3, rotation_x, rotation_y, rotation_z
from headsim.paper import ENCODER_RESOLUTION_RAD

__all__ = [
    "ENCODER_RESOLUTION",
    "camera_centre",
    "eye_from_camera_rotation",
    "head_from_camera",
    "head_to_camera",
    "head_to_world",
    "world_from_head",
    "world_to_head",
]

#: The geometry's default eye-motor encoder step: the paper's head's, rad (Sec. VI).
ENCODER_RESOLUTION = ENCODER_RESOLUTION_RAD


def world_from_head(theta1: ArrayLike, theta2: ArrayLike, d1: float, a2: float) -> np.ndarray:
    """The neck's D-H transform W_T_H of eq. (1), (..., 4, 4).

    theta1: neck yaw about W's z, rad; theta2: neck pitch, rad, positive looks up;
    both broadcast against each other.  d1, a2: D-H parameters, m.
    """
    t1, t2 = np.broadcast_arrays(np.asarray(theta1, float), np.asarray(theta2, float))
    c1, s1, c2, s2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
    zero, one = np.zeros_like(t1), np.ones_like(t1)
    rows = [
        [c1, -s1 * s2, -s1 * c2, a2 * s1 * s2],
        [s1, c1 * s2, c1 * c2, -a2 * c1 * s2],
        [zero, -c2, s2, a2 * c2 + d1],
        [zero, zero, zero, one],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def head_to_world(
    points_h: ArrayLike, theta1: ArrayLike, theta2: ArrayLike, d1: float, a2: float
) -> np.ndarray:
    """Map points (..., 3) from H to W through eq. (3); angles broadcast with the points' lead."""
    p = points3(points_h, "points_h")
    t = world_from_head(theta1, theta2, d1, a2)
    return np.einsum("...ij,...j->...i", t[..., :3, :3], p) + t[..., :3, 3]


def world_to_head(
    points_w: ArrayLike, theta1: ArrayLike, theta2: ArrayLike, d1: float, a2: float
) -> np.ndarray:
    """Map points (..., 3) from W to H, the inverse of :func:`head_to_world`."""
    p = points3(points_w, "points_w")
    t = world_from_head(theta1, theta2, d1, a2)
    return np.einsum("...ji,...j->...i", t[..., :3, :3], p - t[..., :3, 3])


def eye_from_camera_rotation(
    inward: float, mount_yaw_rad: float, mount_pitch_rad: float = 0.0, mount_roll_rad: float = 0.0
) -> np.ndarray:
    """Rotation (3, 3) of a camera's OpenCV frame in its eye frame (eye angle 0).

    The eye frame is parallel to H.  ``inward``: the camera's inward sign
    (``names.EYE_CAMERAS[i].inward``, +1 or -1).  Mount yaw turns the camera
    inward like the eye angle (about +y for Ca1, -y for Ca2); pitch turns it up
    (about its x); roll turns it about its optical axis.
    """
    return (
        rotation_y(inward * mount_yaw_rad)
        @ rotation_x(mount_pitch_rad)
        @ rotation_z(mount_roll_rad)
    )


def camera_centre(camera: int, baseline: float) -> np.ndarray:
    """Optical centre of camera 1 or 2 in H, (3,), m: (-D/2, 0, 0) or (+D/2, 0, 0)."""
    sign = _camera_sign(camera)
    return np.array([sign * baseline / 2.0, 0.0, 0.0])


def head_from_camera(
    camera: int, yaw: ArrayLike, baseline: float, nodal: float = 0.0, side: float = 0.0
) -> np.ndarray:
    """Pose H_T_Ci of camera 1 or 2, (..., 4, 4).

    yaw: the camera's true yaw, rad (eye angle plus mount offset), positive
    inwards.  Camera 1 turns about H's +y by ``yaw``, camera 2 by ``-yaw``, so the
    optical axis in H is ``(sin yaw, 0, cos yaw)`` for camera 1 and
    ``(-sin yaw, 0, cos yaw)`` for camera 2.  ``nodal``/``side``, m: the optical
    centre sits that far from the yaw axis along the optical axis and the camera's x.
    """
    sign = _camera_sign(camera)
    psi = -sign * np.asarray(yaw, float)  # rotation about +y: +yaw for Ca1, -yaw for Ca2
    c, s = np.cos(psi), np.sin(psi)
    t = np.zeros((*psi.shape, 4, 4))
    t[..., 0, 0], t[..., 0, 2], t[..., 2, 0], t[..., 2, 2] = c, s, -s, c
    t[..., 1, 1] = t[..., 3, 3] = 1.0
    t[..., 0, 3] = sign * baseline / 2.0 + c * side + s * nodal
    t[..., 2, 3] = -s * side + c * nodal
    return t


def head_to_camera(
    points_h: ArrayLike,
    camera: int,
    yaw: ArrayLike,
    baseline: float,
    nodal: float = 0.0,
    side: float = 0.0,
) -> np.ndarray:
    """Points (..., 3) in H expressed in camera i's frame, m; arguments as in ``head_from_camera``.

    The inverse of :func:`head_from_camera` applied to the points, written out
    (no 4 x 4 per point): rotate ``p - A_i`` about y by ``-yaw`` (Ca1) or ``+yaw``
    (Ca2), A_i the yaw axis, then subtract the optical centre's offset (side, 0, nodal).
    """
    p = points3(points_h, "points_h")
    sign = _camera_sign(camera)
    psi = -sign * np.asarray(yaw, float)
    c, s = np.cos(psi), np.sin(psi)
    dx, dy, dz = p[..., 0] - sign * baseline / 2.0, p[..., 1], p[..., 2]
    return np.stack(
        np.broadcast_arrays(c * dx - s * dz - side, dy, s * dx + c * dz - nodal), axis=-1
    )


def _camera_sign(camera: int) -> float:
    if camera not in (1, 2):
        raise ValueError(f"camera must be 1 or 2, got {camera!r}")
    return -1.0 if camera == 1 else 1.0
