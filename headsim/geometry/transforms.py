"""Rigid transforms and rotations: building, inverting and comparing poses.

A pose ``a_from_b`` is a 4 x 4 homogeneous transform that maps points in frame
b to frame a (metres); rotations are 3 x 3, angles in radians, right-handed
(frames and signs: docs/equations.md).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "apply_transform",
    "frame_deviation",
    "homogeneous",
    "invert_transform",
    "points3",
    "rotation_angle",
    "rotation_x",
    "rotation_y",
    "rotation_z",
]


def points3(points: ArrayLike, name: str) -> np.ndarray:
    """``points`` as floats of shape (..., 3), else ValueError naming them ``name``."""
    p = np.asarray(points, dtype=float)
    if p.ndim == 0 or p.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3), got {p.shape}")
    return p


def homogeneous(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """The 4 x 4 transform of a rotation (3, 3) and a translation (3,), m."""
    transform = np.eye(4)
    transform[:3, :3] = rotation
    transform[:3, 3] = translation
    return transform


def invert_transform(transform: np.ndarray) -> np.ndarray:
    """Inverse of a rigid 4 x 4 transform."""
    rotation, translation = transform[:3, :3], transform[:3, 3]
    return homogeneous(rotation.T, -rotation.T @ translation)


def apply_transform(dst_from_src: np.ndarray, points_src: np.ndarray) -> np.ndarray:
    """Points (N, 3) in frame dst of points (N, 3) in frame src, m."""
    points_src = np.atleast_2d(np.asarray(points_src, dtype=float))
    return points_src @ dst_from_src[:3, :3].T + dst_from_src[:3, 3]


def rotation_x(angle: float) -> np.ndarray:
    """Rotation about x by ``angle``, rad."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(angle: float) -> np.ndarray:
    """Rotation about y by ``angle``, rad."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotation_z(angle: float) -> np.ndarray:
    """Rotation about z by ``angle``, rad."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_angle(rotation: np.ndarray) -> float:
    """Angle of a rotation matrix, rad."""
    cos = (float(np.trace(rotation)) - 1.0) / 2.0
    return math.acos(min(1.0, max(-1.0, cos)))


def frame_deviation(estimate: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """(rotation angle rad, translation distance m) between two poses of one frame (4, 4)."""
    delta = invert_transform(truth) @ estimate
    return rotation_angle(delta[:3, :3]), float(np.linalg.norm(delta[:3, 3]))
