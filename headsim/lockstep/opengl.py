"""Every head's eye canvases drawn on the CPU through the classic OpenGL renderer.

One OpenGL context for all heads: each head's scene is updated in turn and drawn at the
canvas's exact size (times the supersampling), with the projection and viewport the
classic renderer uses for a whole frame, so its pixels are the classic renderer's
(:class:`headsim.sim.render.EyeRenderer`).  Tiling many views into one framebuffer and
reading it back once was measured and dropped: on llvmpipe it cost more CPU per image
(0.80-0.91 against 0.75 ms at 256 x 192), and a tile away from the origin moved a pixel
by one grey level now and then (float32 viewport arithmetic).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import mujoco
import numpy as np

from headsim.sim import names
from headsim.sim.backend import INSTALL_HINT, RenderBackendError, check_backend
from headsim.sim.gl_window import Window, draw_window
from headsim.sim.mujoco_renderer import check_renderer, make_current, mjr_context, use_model


@dataclass(frozen=True)
class EyeView:
    """One eye canvas to draw: a head's model and data, its camera, the canvas size (px)
    and the supersampling (the camera renders ``supersample`` x the canvas)."""

    model: mujoco.MjModel
    data: mujoco.MjData
    camera: str
    canvas_px: tuple[int, int]
    supersample: int


class ViewRenderer:
    """One OpenGL context that draws many heads' eye canvases in turn.

    ``model``: a model of the scene (its assets are uploaded once; every view drawn must
    share them).  ``largest_px``: the largest (width, height) a view will render.
    """

    def __init__(self, model: mujoco.MjModel, largest_px: tuple[int, int]) -> None:
        check_backend()
        self.largest_px = largest_px
        width, height = largest_px
        saved = (model.vis.global_.offwidth, model.vis.global_.offheight)
        model.vis.global_.offwidth, model.vis.global_.offheight = width, height
        try:
            self._renderer = mujoco.Renderer(model, height=height, width=width)
        except Exception as err:  # GL context creation failed
            raise RenderBackendError(
                f"could not create an off-screen OpenGL context for {width}x{height}: {err}. "
                f"{INSTALL_HINT}"
            ) from err
        finally:
            model.vis.global_.offwidth, model.vis.global_.offheight = saved
        check_renderer(self._renderer)
        self._option = mujoco.MjvOption()
        self._option.geomgroup[names.HEAD_VISUAL_GROUP] = 0  # as the classic eye renderer
        #: Canvases drawn.
        self.views = 0
        #: CPU seconds of this process (llvmpipe's threads included) spent in OpenGL's
        #: draws and reads: the rest of a step's CPU is the host's.
        self.opengl_cpu_s = 0.0

    def draw(self, views: Sequence[EyeView]) -> list[np.ndarray]:
        """Each view's pinhole canvas, uint8 (h, w, 3), supersampling area-averaged out."""
        kinds = {(view.canvas_px, view.supersample) for view in views}
        if len(kinds) != 1:
            return [image for view in views for image in self.draw([view])]
        ((canvas_px, k),) = kinds
        width, height = k * canvas_px[0], k * canvas_px[1]
        if width > self.largest_px[0] or height > self.largest_px[1]:
            raise ValueError(
                f"a {width}x{height} view does not fit this renderer's "
                f"{self.largest_px[0]}x{self.largest_px[1]} buffer"
            )
        renderer = self._renderer
        context = mjr_context(renderer)
        make_current(renderer)
        rect = mujoco.MjrRect(0, 0, width, height)
        pixels = np.empty((len(views), height, width, 3), np.uint8)
        for view, read in zip(views, pixels, strict=True):
            use_model(renderer, view.model)
            renderer.update_scene(view.data, camera=view.camera, scene_option=self._option)
            start = time.process_time()
            mujoco.mjr_render(rect, renderer.scene, context)
            mujoco.mjr_readPixels(read, None, rect, context)
            self.opengl_cpu_s += time.process_time() - start
        self.views += len(views)
        # The stack is area-averaged as one tall image: each k x k block lies within one
        # view (heights are whole multiples of k), and turning the rows upright after
        # (OpenGL's run bottom-up) moves whole blocks, so the pixels are the same.
        canvases: np.ndarray = pixels.reshape(-1, width, 3)
        if k > 1:
            size = (canvas_px[0], canvas_px[1] * len(views))
            canvases = cv2.resize(canvases, size, interpolation=cv2.INTER_AREA)
        upright = canvases.reshape(len(views), canvas_px[1], canvas_px[0], 3)[:, ::-1]
        return list(np.ascontiguousarray(upright))

    def draw_window(self, view: EyeView, rect: Window) -> np.ndarray:
        """The canvas pixels of ``rect`` of ``view``, uint8 (h, w, 3): drawn as the classic
        renderer draws a window (the whole frame's projection, clipped to it:
        :func:`~headsim.sim.gl_window.draw_window`), so they are the frame's crop."""
        renderer, k = self._renderer, view.supersample
        full = (k * view.canvas_px[0], k * view.canvas_px[1])
        use_model(renderer, view.model)
        renderer.update_scene(view.data, camera=view.camera, scene_option=self._option)
        make_current(renderer)
        start = time.process_time()
        pixels = draw_window(renderer, rect, k, full)
        self.opengl_cpu_s += time.process_time() - start
        self.views += 1
        pixels = np.ascontiguousarray(pixels[::-1])  # OpenGL's rows run bottom-up
        if k > 1:
            pixels = cv2.resize(pixels, (rect.width, rect.height), interpolation=cv2.INTER_AREA)
        return pixels

    def close(self) -> None:
        """Free the OpenGL context."""
        self._renderer.close()


__all__ = ["EyeView", "ViewRenderer"]
