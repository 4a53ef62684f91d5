"""The head frame H from a stereo calibration (how far two poses differ: geometry.transforms).

Frames (docs/concepts/frames.md): Ci is camera i's OpenCV frame, H the head frame.
OpenCV's stereo extrinsics ``(R, T)`` map camera 1 to camera 2,
``x2 = R x1 + T``, i.e. ``cam2_from_cam1 = [[R, T], [0, 1]]``.  Units: m, rad.

**H from the calibration** (:func:`head_from_cam1_from_extrinsics`): the origin
is the midpoint of the two calibrated optical centres, x points from C1 to C2,
y is the mean of the two cameras' y axes made orthogonal to x, z = x cross y.
At eye angle 0 both cameras are turned only about the eye axes, which are
parallel to H's y, so with zero mount pitch and roll this is H exactly (up to
calibration error) for any mount yaws.  The paper's own construction, a
rotation by the eye's calibrated initial direction about y_c1 and a shift of
D/2 along x (:func:`head_from_cam1_from_eye`), is there for comparison.
"""

from __future__ import annotations

import numpy as np

from headsim.geometry.transforms import invert_transform, rotation_y


def head_from_cam1_from_extrinsics(cam2_from_cam1: np.ndarray) -> np.ndarray:
    """H built from the stereo extrinsics: camera 1's pose in it (4, 4).

    Origin: midpoint of C1 and C2.  x: from C1 to C2.  y: the mean of the two
    cameras' y axes, made orthogonal to x.  z = x cross y.  Exact at eye angle
    0 when the mounts are turned only about the eye axes (H's y).
    """
    cam1_from_cam2 = invert_transform(cam2_from_cam1)
    c2 = cam1_from_cam2[:3, 3]  # C2 in camera 1's frame; C1 is the origin
    x_axis = c2 / np.linalg.norm(c2)
    y_mean = np.array([0.0, 1.0, 0.0]) + cam1_from_cam2[:3, 1]
    y_axis = y_mean - (y_mean @ x_axis) * x_axis
    y_axis /= np.linalg.norm(y_axis)
    z_axis = np.cross(x_axis, y_axis)
    cam1_from_head = np.eye(4)
    cam1_from_head[:3, :3] = np.column_stack([x_axis, y_axis, z_axis])
    cam1_from_head[:3, 3] = c2 / 2
    return invert_transform(cam1_from_head)


def head_from_cam1_from_eye(initial_direction_rad: float, baseline_m: float) -> np.ndarray:
    """The paper's H (Sec. VI-B): turn by camera 1's initial direction about y_c1, shift D/2.

    Camera 1 sits at (-D/2, 0, 0) in H, turned inward (towards +x) by
    ``initial_direction_rad`` about H's y.  That angle must be the optical
    axis's, i.e. the mount yaw: the Sec. V calibration measures the image
    centre's ray instead; subtract :attr:`CameraCalibration.centre_ray_yaw_rad`
    from it first.
    """
    head_from_cam1 = np.eye(4)
    head_from_cam1[:3, :3] = rotation_y(initial_direction_rad)
    head_from_cam1[:3, 3] = [-baseline_m / 2, 0.0, 0.0]
    return head_from_cam1
