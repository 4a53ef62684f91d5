"""A camera's projection with its lens (OpenCV's radial k1, k2): points to pixels and back.

How the lens is put on images is :mod:`headsim.sim.imperfections.distortion`.
Pixels as in OpenCV (centres at integer coordinates).
"""

from __future__ import annotations

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
