"""Both eye cameras of many heads at once, through MuJoCo Warp's batch ray-cast renderer.

N *worlds* share one compiled model (one head's settings: cameras, mounts, lengths)
and differ in their joint angles.  :class:`BatchRenderer` renders both eye cameras of
every world in one call and then treats each image as :class:`headsim.sim.render`
does a full frame: the supersampled pinhole image averaged down, the lens's
distortion by remap (:func:`headsim.sim.optics.apply_canvas`) and Gaussian noise, from
a stream of each world's own.  The head's own geoms (group 3) stay hidden, as from
the classic renderer.

This module is the one adapter to ``mujoco_warp`` and ``warp`` (the ``batch`` extra:
``pip install 'headsim[batch]'``); they are imported only when a renderer is made.
Warp runs on the CPU by default, on a GPU with ``device="cuda"`` where it finds one.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import mujoco
import numpy as np

from headsim.errors import BadInput
from headsim.sim.optics import GaussianNoise, apply_canvas
from headsim.sim.simulator import HeadSim

#: The devices a batch renderer runs on.
DEVICES = ("cpu", "cuda")
#: The noise stream of batch images, apart from the classic renderer's.
BATCH_STREAM = 0xBA7C


class BatchError(BadInput, ValueError):
    """A batch renderer cannot be made as asked: what is missing and what is allowed."""


@dataclass(frozen=True)
class _Warp:
    wp: ModuleType
    mjw: ModuleType


def _warp() -> _Warp:
    try:
        wp = importlib.import_module("warp")
        # Warnings only (not each kernel module's load time), before mujoco_warp starts Warp.
        wp.config.log_level = wp.LOG_WARNING
        mjw = importlib.import_module("mujoco_warp")
    except ImportError as err:
        raise BatchError(
            f"the batch renderer needs MuJoCo Warp ({err.name} is not installed); "
            "allowed: pip install 'headsim[batch]'"
        ) from None
    return _Warp(wp, mjw)


def cuda_available() -> bool:
    """Whether Warp finds a CUDA device here (False without the batch extra)."""
    try:
        return bool(_warp().wp.is_cuda_available())
    except BatchError:
        return False


class BatchRenderer:
    """Both eye cameras of ``nworld`` copies of ``sim``'s head and scene.

    ``render(qpos)`` takes each world's joint positions, (nworld, nq), and returns
    (nworld, 2, height, width, 3) uint8 images, camera Ca1 then Ca2.  ``device``:
    ``"cpu"`` or ``"cuda"``; ``samples_per_pixel``: Warp's sub-pixel rays (anti-aliasing).
    """

    def __init__(
        self,
        sim: HeadSim,
        nworld: int,
        *,
        device: str = "cpu",
        samples_per_pixel: int = 1,
        seed: int | None = None,
    ) -> None:
        if not (isinstance(nworld, int) and nworld >= 1):
            raise BatchError(f"nworld must be a whole number >= 1, got {nworld!r}")
        if device not in DEVICES:
            raise BatchError(f"device must be one of {', '.join(DEVICES)}, got {device!r}")
        if not (isinstance(samples_per_pixel, int) and 1 <= samples_per_pixel <= 64):
            raise BatchError(f"samples_per_pixel must be 1 to 64, got {samples_per_pixel!r}")
        warp = _warp()
        if device == "cuda" and not warp.wp.is_cuda_available():
            raise BatchError("device 'cuda': Warp finds no CUDA device here; allowed: cpu")
        self.device, self.nworld = device, nworld
        self.model: mujoco.MjModel = sim.model
        self._warp = warp
        self._cameras = [int(self.model.camera(name).id) for name in sim.names.cameras]
        self._canvases = sim.built.canvases
        self._supersample = sim.settings.render.supersample
        self._noise = tuple(GaussianNoise.of(c.noise_std) for c in sim.settings.cameras)
        self._seed = sim.settings.seed if seed is None else seed
        self._frame = 0
        resolution = [tuple(int(v) for v in self.model.cam_resolution[c]) for c in self._cameras]
        self._resolution = resolution
        with warp.wp.ScopedDevice(device):
            self._m = warp.mjw.put_model(self.model)
            self._d = warp.mjw.put_data(self.model, mujoco.MjData(self.model), nworld=nworld)
            self._rc = warp.mjw.create_render_context(
                self.model,
                nworld=nworld,
                cam_res=resolution,
                render_rgb=True,
                render_depth=False,
                cam_active=self._cameras,
                samples_per_pixel=samples_per_pixel,
                deterministic=True,
            )
            self._out = [warp.wp.zeros((nworld, h, w), dtype=warp.wp.vec3) for w, h in resolution]

    def describe(self) -> str:
        """Which device ran, in words."""
        return f"MuJoCo Warp on {self.device}: {self.nworld} worlds x 2 cameras"

    def render(self, qpos: np.ndarray) -> np.ndarray:
        """Each world's two eye images at joint positions ``qpos`` (nworld, nq)."""
        q = np.asarray(qpos, dtype=float)
        if q.shape != (self.nworld, self.model.nq):
            raise BatchError(
                f"qpos must have shape ({self.nworld}, {self.model.nq}), one row per world, "
                f"got {q.shape}"
            )
        wp, mjw = self._warp.wp, self._warp.mjw
        with wp.ScopedDevice(self.device):
            self._d.qpos.assign(q.astype(np.float32))
            mjw.kinematics(self._m, self._d)
            mjw.camlight(self._m, self._d)
            mjw.render(self._m, self._d, self._rc)
            for index, out in enumerate(self._out):
                mjw.get_rgb(self._rc, index, out)
            raw = [out.numpy() for out in self._out]
        images = [[self._finish(raw[c][w], c, w) for c in range(2)] for w in range(self.nworld)]
        self._frame += 1
        return np.stack([np.stack(pair) for pair in images])

    def _finish(self, rgb: np.ndarray, camera: int, world: int) -> np.ndarray:
        """A world's raw float image as the classic renderer finishes a frame."""
        k = self._supersample
        if k > 1:
            h, w = rgb.shape[0] // k, rgb.shape[1] // k
            rgb = rgb.reshape(h, k, w, k, 3).mean(axis=(1, 3))
        image = np.clip(rgb * 255.0 + 0.5, 0.0, 255.0).astype(np.uint8)
        image = apply_canvas(image, self._canvases[camera])
        key: Any = (self._seed, BATCH_STREAM, world, camera)
        return self._noise[camera].apply(image, key, self._frame)


__all__ = ["DEVICES", "BatchError", "BatchRenderer", "cuda_available"]
