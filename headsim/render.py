"""Off-screen rendering of the eye cameras: MuJoCo pinhole render, lens, noise.

One :class:`mujoco.Renderer` per canvas size is created lazily and reused.
The head's own geoms (group ``names.HEAD_VISUAL_GROUP``) are hidden from the
eye cameras.  Every call of :meth:`EyeRenderer.render` is one render and is
counted.
"""

from __future__ import annotations

import mujoco
import numpy as np

from headsim import names
from headsim.backend import INSTALL_HINT, RenderBackendError, check_backend
from headsim.optics import DistortionCanvas, GaussianNoise, apply_canvas
from headsim.settings import CameraSettings


class EyeRenderer:
    """Renders the two eye cameras of one compiled model to 8-bit RGB arrays."""

    def __init__(
        self,
        model: mujoco.MjModel,
        cameras: tuple[CameraSettings, CameraSettings],
        canvases: tuple[DistortionCanvas, DistortionCanvas],
        seed: int = 0,
    ) -> None:
        self._model = model
        self._cameras = cameras
        self._canvases = canvases
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}
        self._option = mujoco.MjvOption()
        self._option.geomgroup[names.HEAD_VISUAL_GROUP] = 0
        # One noise stream per camera: image k of camera i gets the noise drawn
        # from (seed, i, k), whatever else was rendered.
        self._seed = seed
        self._noise = tuple(GaussianNoise.of(camera.noise_std) for camera in cameras)
        self._taken = [0, 0]
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
        renderer = self._renderer(canvas.size)
        renderer.update_scene(data, camera=names.CAMERAS[index], scene_option=self._option)
        image = apply_canvas(renderer.render(), canvas)
        self.render_count += 1
        frame = self._taken[index]
        self._taken[index] += 1
        return self._noise[index].apply(image, (self._seed, index), frame)

    def close(self) -> None:
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()
