"""What both cameras see from one head pose: a pure snapshot of the head's geometry.

Frames as in docs/equations.md: W world, H head, each camera's OpenCV frame;
transforms are 4 x 4 ``dst_from_src``, metres.  Placement and checks only: a
view carries the true intrinsics, never what the head has measured.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from headsim.geometry.camera_model import PinholeCamera
from headsim.geometry.transforms import apply_transform

__all__ = ["StereoView"]


@dataclass(frozen=True)
class StereoView:
    """Both cameras' intrinsics and poses, and the head's pose, at one instant."""

    cameras: tuple[PinholeCamera, PinholeCamera]
    camera_from_world: tuple[np.ndarray, np.ndarray]
    world_from_head: np.ndarray

    def sees_whole(self, points_world: np.ndarray, radius_m: float = 0.0) -> np.ndarray:
        """(N,) whether each world point images whole inside both cameras.

        The point's image, plus its apparent radius (a ball of ``radius_m``) and
        2 px, lies inside the image.
        """
        points_world = np.atleast_2d(points_world)
        ok = np.ones(len(points_world), dtype=bool)
        for cam, camera_from_world in zip(self.cameras, self.camera_from_world, strict=True):
            points_cam = apply_transform(camera_from_world, points_world)
            uv = cam.project(points_cam)
            depth = points_cam[:, 2]
            margin = 2.0 + max(cam.kx, cam.ky) * radius_m / np.maximum(depth, 1e-9)
            with np.errstate(invalid="ignore"):
                ok &= (
                    (depth > 0)
                    & (uv[:, 0] >= margin)
                    & (uv[:, 0] <= cam.width - 1 - margin)
                    & (uv[:, 1] >= margin)
                    & (uv[:, 1] <= cam.height - 1 - margin)
                )
        return ok
