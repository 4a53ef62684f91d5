"""Both eyes of many heads ray-cast by MuJoCo Warp in one call, markers found on the device.

The device path of lockstep heads (``device="cuda"``; Warp's CPU device runs the same code
in the tests).  Every world is one head of one model: its poses are uploaded from the
lockstep batch's arrays (no per-head data), both eye cameras are cast in one
``mujoco_warp.render`` call at their exact size with ``samples_per_pixel`` x
``samples_per_pixel`` rays a pixel (anti-aliasing on the device), and
:meth:`WarpEyes.marker_sums` reduces each image to a marker's weighted sums on the
device, so only (weight, u, v) per image comes back.  :meth:`WarpEyes.images` brings
the pinhole canvases back when the caller needs pixels (a Gym observation).

Warp is reached through :func:`headsim.sim.batch.check_device` (its one adapter: the
quiet start and the install hint); the kernels live in
:mod:`headsim.lockstep.warp_kernels`, imported only here.
"""

from __future__ import annotations

import importlib
from typing import Any

import mujoco
import numpy as np

from headsim.sim.batch import check_device
from headsim.vision.markers import COLOURS


class WarpEyes:
    """``nworld`` copies of ``model``'s two eye cameras (``cameras``: their names), each
    image ``size`` (w, h) px, cast on ``device`` with ``samples_per_pixel`` rays a pixel
    per axis."""

    def __init__(
        self,
        model: mujoco.MjModel,
        cameras: tuple[str, str],
        size: tuple[int, int],
        nworld: int,
        device: str = "cuda",
        samples_per_pixel: int = 2,
    ) -> None:
        warp = check_device(device)
        self._wp, self._mjw = warp.wp, warp.mjw
        self._kernels: Any = importlib.import_module("headsim.lockstep.warp_kernels")
        self.device, self.nworld, self.size = device, nworld, size
        self.samples_per_pixel = samples_per_pixel
        ids = [int(model.camera(name).id) for name in cameras]
        wp, mjw = self._wp, self._mjw
        with wp.ScopedDevice(device):
            self._m = mjw.put_model(model)
            self._d = mjw.put_data(model, mujoco.MjData(model), nworld=nworld)
            self._rc = mjw.create_render_context(
                model,
                nworld=nworld,
                cam_res=[size, size],
                render_rgb=True,
                render_depth=False,
                cam_active=ids,
                use_precomputed_rays=True,
                samples_per_pixel=samples_per_pixel,
                deterministic=True,
            )
            self._sums = wp.zeros((nworld, 2, 3), dtype=wp.float64)
        #: Warp render calls made.
        self.calls = 0

    def describe(self) -> str:
        """The renderer, in words."""
        return (
            f"MuJoCo Warp on {self.device}: {self.nworld} heads x 2 cameras in one call, "
            f"{self.samples_per_pixel}x{self.samples_per_pixel} rays a pixel"
        )

    def cast(self, poses: dict[str, np.ndarray]) -> None:
        """Cast every world's two images from ``poses`` (each of :data:`POSE_FIELDS`, rows
        per world, as ``mujoco.batch`` binds them)."""
        wp, mjw, d = self._wp, self._mjw, self._d
        n = self.nworld
        with wp.ScopedDevice(self.device):
            d.geom_xpos.assign(poses["geom_xpos"].reshape(n, -1, 3).astype(np.float32))
            d.geom_xmat.assign(poses["geom_xmat"].reshape(n, -1, 3, 3).astype(np.float32))
            d.cam_xpos.assign(poses["cam_xpos"].reshape(n, -1, 3).astype(np.float32))
            d.cam_xmat.assign(poses["cam_xmat"].reshape(n, -1, 3, 3).astype(np.float32))
            if d.light_xpos.shape[1]:
                d.light_xpos.assign(poses["light_xpos"].reshape(n, -1, 3).astype(np.float32))
                d.light_xdir.assign(poses["light_xdir"].reshape(n, -1, 3).astype(np.float32))
            mjw.refit_bvh(self._m, d, self._rc)
            mjw.render(self._m, d, self._rc)
        self.calls += 1

    def synchronize(self) -> None:
        """Wait until the device has done what was launched."""
        self._wp.synchronize_device(self.device)

    def images(self) -> np.ndarray:
        """The last cast's pinhole canvases, copied back: (nworld, 2, h, w, 3) uint8 RGB."""
        width, height = self.size
        packed = self._rc.rgb_data.numpy()  # (nworld, 2 w h) ABGR words, camera by camera
        bgra = packed.view(np.uint8).reshape(self.nworld, 2, height, width, 4)
        return np.ascontiguousarray(bgra[..., 2::-1])

    def marker_sums(self, colour: str, threshold: float = 0.2) -> np.ndarray:
        """Each image's (sum w, sum w u, sum w v) over the pixels whose colour weight w
        (:func:`headsim.vision.markers.colour_weight`) exceeds ``threshold``, reduced on
        the device: (nworld, 2, 3).  The centroid is (u, v) = sums[1:] / sums[0]."""
        if colour not in COLOURS:
            raise ValueError(f"unknown marker colour {colour!r}; allowed: {', '.join(COLOURS)}")
        wp = self._wp
        width, height = self.size
        with wp.ScopedDevice(self.device):
            self._sums.zero_()
            wp.launch(
                self._kernels.marker_sums,
                dim=(self.nworld, 2, width * height),
                inputs=[
                    self._rc.rgb_data,
                    self._rc.rgb_adr,
                    width,
                    wp.vec3(*(float(c) for c in COLOURS[colour])),
                    float(threshold * 255.0),
                ],
                outputs=[self._sums],
            )
            return np.asarray(self._sums.numpy())


def centroids(sums: np.ndarray) -> np.ndarray:
    """(…, 2) centroids (u, v) px from :meth:`WarpEyes.marker_sums`; NaN where no pixel
    had the colour."""
    weight = sums[..., 0:1]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(weight > 0, sums[..., 1:] / np.where(weight > 0, weight, 1.0), np.nan)


__all__ = ["WarpEyes", "centroids"]
