"""Off-screen rendering of the eye cameras: MuJoCo pinhole render, lens, noise.

One :class:`mujoco.Renderer` per canvas size is created lazily and reused.
The head's own geoms (group ``names.HEAD_VISUAL_GROUP``) are hidden from the
eye cameras.  Every call of :meth:`EyeRenderer.render` is one render and is
counted.
"""

from __future__ import annotations

import cv2
import mujoco
import numpy as np

from headsim import names
from headsim.backend import INSTALL_HINT, RenderBackendError, check_backend
from headsim.optics import DistortionCanvas, add_noise, apply_canvas
from headsim.settings import CameraSettings


class EyeRenderer:
    """Renders the two eye cameras of one compiled model to 8-bit RGB arrays."""

    def __init__(
        self,
        model: mujoco.MjModel,
        cameras: tuple[CameraSettings, CameraSettings],
        canvases: tuple[DistortionCanvas, DistortionCanvas],
        seed: int = 0,
        supersample: int = 1,
    ) -> None:
        """``supersample``: the model's cameras render at this many times each
        canvas's size (``headsim.settings.RenderFidelity``); images are area-averaged
        back to the canvas."""
        self._model = model
        self._supersample = supersample
        self._cameras = cameras
        self._canvases = canvases
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}
        self._option = mujoco.MjvOption()
        self._option.geomgroup[names.HEAD_VISUAL_GROUP] = 0
        # One noise stream per camera, so each camera's noise depends only on
        # the seed and on how many images that camera has taken.
        self._noise = tuple(np.random.default_rng([seed, index]) for index in range(2))
        self.render_count = 0

    def _renderer(self, size: tuple[int, int]) -> mujoco.Renderer:
        if size not in self._renderers:
            backend = check_backend()
            width, height = size
            try:
                self._renderers[size] = mujoco.Renderer(self._model, height=height, width=width)
            except ValueError as err:  # larger than the model's off-screen buffer
                raise ValueError(f"cannot render {width}x{height}: {err}") from err
            except Exception as err:  # GL context creation failed
                raise RenderBackendError(
                    f"could not create an off-screen OpenGL context with MUJOCO_GL={backend}: {err}. "
                    f"{INSTALL_HINT}"
                ) from err
        return self._renderers[size]

    def render(self, data: mujoco.MjData, index: int) -> np.ndarray:
        """Render camera ``index`` (0 = Ca1, 1 = Ca2) from ``data``: (H, W, 3) uint8."""
        canvas = self._canvases[index]
        k = self._supersample
        renderer = self._renderer((k * canvas.size[0], k * canvas.size[1]))
        renderer.update_scene(data, camera=names.CAMERAS[index], scene_option=self._option)
        frame = renderer.render()
        if k > 1:
            frame = cv2.resize(frame, canvas.size, interpolation=cv2.INTER_AREA)
        image = apply_canvas(frame, canvas)
        self.render_count += 1
        return add_noise(image, self._cameras[index].noise_std, self._noise[index])

    def close(self) -> None:
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()
