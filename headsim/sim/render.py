"""Off-screen rendering of the eye cameras: MuJoCo pinhole render, lens, noise.

One :class:`mujoco.Renderer` (an OpenGL context) per scene and context state (the
assets it uploads, :func:`context_key`, and what else it is made with,
:func:`context_state`: multisampling, clip and fog distances, read when an image is
drawn) is kept in a small process-wide pool and reused by every simulator of that scene
and state, whatever its head, within a run and across the jobs of a worker: creating one
costs 0.08-0.2 s.  Its off-screen buffer is at least as large as every model it drew
needed (one whose lens needs a larger canvas grows it once), and an image is drawn in
its corner at its own size, so an image never depends on what the process drew before.

A *window* is a sub-rectangle of a camera's image (for a distorted camera:
the region of its pinhole canvas that the window's pixels sample), drawn as
the whole frame, with the same projection and the viewport moved by whole
pixels, its geometry clipped a few pixels outside the window so that only the
window is rasterised.  Every vertex lands where it does in the frame, less the
window's offset, so the window's pixels are the full frame's crop (a window
drawn as a camera of its own, with a shifted principal point, rounds its
projection otherwise and flips an MSAA sample now and then).  Noise included:
a window gets the noise of image k of its camera's whole frame there, drawn for
the window's rows only.  The
head's own geoms (group ``names.HEAD_VISUAL_GROUP``) are hidden from the eye
cameras.  Every image is
one render and is counted, with its pixels in full-frame equivalents.
"""

from __future__ import annotations

import hashlib
import itertools
from collections import OrderedDict
from collections.abc import Hashable

import cv2
import mujoco
import numpy as np

from headsim.sim import imperfections, names
from headsim.sim.backend import INSTALL_HINT, RenderBackendError, check_backend
from headsim.sim.gl_window import Window, draw_window
from headsim.sim.imperfections.distortion import DistortionCanvas
from headsim.sim.mujoco_renderer import check_renderer, make_current, mjr_context, use_model
from headsim.sim.settings import CameraSettings

#: Renderers kept per process (one per head and scene); the least recently used goes first.
POOL_SIZE = 4
_POOL: OrderedDict[Hashable, mujoco.Renderer] = OrderedDict()
#: Renderers created in this process (the pool's misses), for the bench and tests.
created = 0
#: Which version of a changed texture each pooled context holds, by (context key, texture
#: id): contexts are shared, so an eye renderer whose model's texture changed uploads it
#: again before drawing whenever another model's version was drawn there last.
_UPLOADED: dict[tuple[Hashable, int], int] = {}
_versions = itertools.count(1)


#: What an OpenGL context holds of a model (uploaded once): meshes, textures, height
#: fields, skins.  Everything else (cameras, bodies, geom sizes and colours) is read
#: from the model and data at every render.
_CONTEXT_ARRAYS = ("mesh_vert", "mesh_face", "mesh_normal", "tex_data", "hfield_data", "skin_vert")


def context_key(scene: str, model: mujoco.MjModel) -> tuple[str, str]:
    """What identifies the OpenGL context a model needs: its scene and a digest of the
    assets the context uploads (taken when the simulator is built: a texture changed later
    is uploaded, not a new context).  Heads that differ only in their settings (baseline,
    mounts, noise) share one context; :func:`context_state` adds what else it is made
    with."""
    digest = hashlib.sha1()
    for name in _CONTEXT_ARRAYS:
        array = getattr(model, name, None)
        if array is not None:
            digest.update(name.encode())
            digest.update(np.ascontiguousarray(array).tobytes())
    return (str(scene), digest.hexdigest())


def context_state(model: mujoco.MjModel) -> tuple[float, ...]:
    """What ``mjr_makeContext`` reads from ``model`` besides its assets and the off-screen
    buffer's size, read when an image is drawn (a model may change them after it is
    built, as the Gym env's multisampling): the buffer's samples, the shadow map, the
    built-in meshes' tessellation, and the clip, fog and shadow distances (``vis.map`` x
    ``stat.extent``)."""
    quality, scale = model.vis.quality, model.vis.map
    return (
        float(quality.offsamples),
        float(quality.shadowsize),
        float(quality.numslices),
        float(quality.numstacks),
        float(quality.numquads),
        float(model.stat.extent),
        *(float(getattr(scale, name)) for name in _MAP_FIELDS),
    )


#: ``vis.map``'s fields that the context scales by the model's extent.
_MAP_FIELDS = ("znear", "zfar", "fogstart", "fogend", "shadowclip", "shadowscale", "haze")


def _acquire(key: Hashable, model: mujoco.MjModel) -> mujoco.Renderer:
    """The pooled renderer of ``key`` (assets and :func:`context_state`), made from
    ``model``, its off-screen buffer at least ``model``'s (a pooled one too small is made
    again at the larger of both sizes)."""
    global created
    width, height = int(model.vis.global_.offwidth), int(model.vis.global_.offheight)
    renderer = _POOL.pop(key, None)
    if renderer is not None:
        context = mjr_context(renderer)
        if context.offWidth < width or context.offHeight < height:
            width, height = max(width, context.offWidth), max(height, context.offHeight)
            renderer.close()
            renderer = None
    if renderer is None:
        backend = check_backend()
        saved = (model.vis.global_.offwidth, model.vis.global_.offheight)
        model.vis.global_.offwidth, model.vis.global_.offheight = width, height
        try:
            renderer = mujoco.Renderer(model, height=height, width=width)
        except ValueError as err:  # larger than the model's off-screen buffer
            raise ValueError(f"cannot render {width}x{height}: {err}") from err
        except Exception as err:  # GL context creation failed
            raise RenderBackendError(
                f"could not create an off-screen OpenGL context with MUJOCO_GL={backend}: {err}. "
                f"{INSTALL_HINT}"
            ) from err
        finally:
            model.vis.global_.offwidth, model.vis.global_.offheight = saved
        check_renderer(renderer)
        created += 1
        for uploaded in [k for k in _UPLOADED if k[0] == key]:
            del _UPLOADED[
                uploaded
            ]  # a new context holds the textures of the model it was made with
    _POOL[key] = renderer
    while len(_POOL) > POOL_SIZE:
        _, oldest = _POOL.popitem(last=False)
        oldest.close()
    return renderer


def release_renderers() -> None:
    """Close every pooled renderer (their OpenGL contexts)."""
    while _POOL:
        _, renderer = _POOL.popitem()
        renderer.close()
    _UPLOADED.clear()


class EyeRenderer:
    """Renders the two eye cameras of one compiled model to 8-bit RGB arrays.

    ``key``: what identifies the OpenGL context the model needs
    (:func:`context_key`); models with equal keys share one.  None: a context
    of its own.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        cameras: tuple[CameraSettings, CameraSettings],
        canvases: tuple[DistortionCanvas, DistortionCanvas],
        seed: int = 0,
        key: Hashable | None = None,
        supersample: int = 1,
        camera_names: tuple[str, str] = names.CAMERAS,
    ) -> None:
        """``supersample``: the model's cameras render at this many times each
        canvas's size (``headsim.sim.settings.RenderFidelity``); images are area-averaged
        back to the canvas."""
        self._mj_model = model
        self._supersample = supersample
        self._cameras = cameras
        self._canvases = canvases
        self._key: Hashable = key if key is not None else ("own", id(self))
        self._own = key is None
        self._option = mujoco.MjvOption()
        self._option.geomgroup[names.HEAD_VISUAL_GROUP] = 0
        # One image stream per camera: image k of camera i gets the imperfections
        # (its noise) drawn from (seed, i, k), whatever else was rendered.
        self._seed = seed
        self._stages = tuple(
            imperfections.prepare(camera, canvas)
            for camera, canvas in zip(cameras, canvases, strict=True)
        )
        self._taken = [0, 0]
        self._previews = [0, 0]
        self._cam_ids = [
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, name) for name in camera_names
        ]
        self._camera_names = camera_names
        self.render_count = 0
        #: Pixels rendered, in full frames of the camera that rendered them.
        self.rendered_frames = 0.0
        #: The version of each texture changed in the model since it was built, by texture id.
        self._textures: dict[int, int] = {}

    def texture_changed(self, texture_id: int) -> None:
        """The model's ``tex_data`` of ``texture_id`` changed: upload it before the next image."""
        self._textures[texture_id] = next(_versions)

    def _renderer(self) -> mujoco.Renderer:
        key = (self._key, context_state(self._mj_model))
        renderer = _acquire(key, self._mj_model)
        use_model(renderer, self._mj_model)  # the same assets; this model's cameras and bodies
        for texture_id, version in self._textures.items():
            if _UPLOADED.get((key, texture_id)) != version:
                make_current(renderer)
                mujoco.mjr_uploadTexture(self._mj_model, mjr_context(renderer), texture_id)
                _UPLOADED[(key, texture_id)] = version
        return renderer

    def _draw(
        self, data: mujoco.MjData, index: int, rect: Window | None, binning: int = 1
    ) -> np.ndarray:
        """The pinhole canvas of camera ``index``, or its sub-rectangle ``rect``: (h, w, 3);
        with ``binning`` b > 1 the whole canvas at 1/b of its resolution (no supersampling)."""
        canvas = self._canvases[index]
        renderer = self._renderer()
        k = self._supersample
        width_c, height_c = canvas.size
        full_w, full_h = k * width_c, k * height_c
        cam = self._cam_ids[index]
        model = self._mj_model
        saved = None
        if binning > 1:
            # A preview: the same camera at 1/b of the resolution (the sensor binned
            # b x b), no supersampling; the canvas cut to a multiple of b.
            rect = Window(0, 0, width_c - width_c % binning, height_c - height_c % binning)
            out_w, out_h = rect.width // binning, rect.height // binning
            pitch = model.cam_sensorsize[cam] / model.cam_resolution[cam]
            offset_px = model.cam_intrinsic[cam][2:4] / pitch
            window_offset = offset_px + np.array(
                [(k * rect.width - full_w) / 2, (k * rect.height - full_h) / 2]
            )
            saved = (
                model.cam_resolution[cam].copy(),
                model.cam_sensorsize[cam].copy(),
                model.cam_intrinsic[cam].copy(),
            )
            model.cam_resolution[cam] = (out_w, out_h)
            model.cam_sensorsize[cam] = pitch * np.array([k * rect.width, k * rect.height])
            model.cam_intrinsic[cam][2:4] = window_offset * pitch
        try:
            renderer.update_scene(data, camera=self._camera_names[index], scene_option=self._option)
        finally:
            if saved is not None:
                (
                    model.cam_resolution[cam],
                    model.cam_sensorsize[cam],
                    model.cam_intrinsic[cam],
                ) = saved
        make_current(renderer)
        context = mjr_context(renderer)
        if binning > 1:
            viewport = mujoco.MjrRect(0, 0, out_w, out_h)
            mujoco.mjr_render(viewport, renderer.scene, context)
            pixels: np.ndarray = np.empty((out_h, out_w, 3), dtype=np.uint8)
            mujoco.mjr_readPixels(pixels, None, viewport, context)
            self.rendered_frames += (out_w * out_h) / (width_c * height_c)
            return np.ascontiguousarray(pixels[::-1])
        # Supersampled k times (headsim.sim.settings.RenderFidelity): the model's
        # camera renders k x the canvas, and each canvas pixel is the area
        # average of a k x k block; a window is cut on whole blocks.
        if rect is None or (rect.width, rect.height) == (width_c, height_c):
            rect = Window(0, 0, width_c, height_c)
            viewport = mujoco.MjrRect(0, 0, full_w, full_h)
            mujoco.mjr_render(viewport, renderer.scene, context)
            pixels = np.empty((full_h, full_w, 3), dtype=np.uint8)
            mujoco.mjr_readPixels(pixels, None, viewport, context)
        else:
            # A window is drawn as the whole frame (the same projection and
            # viewport: every vertex lands where it does in the frame, so its
            # pixels are the frame's crop), with geometry clipped a few pixels
            # outside it, so that only the window's pixels are rasterised.
            pixels = draw_window(renderer, rect, k, (full_w, full_h))
        self.rendered_frames += (rect.width * rect.height) / (width_c * height_c)
        pixels = np.ascontiguousarray(pixels[::-1])  # OpenGL's rows run bottom-up
        if k > 1:
            pixels = cv2.resize(pixels, (rect.width, rect.height), interpolation=cv2.INTER_AREA)
        return pixels

    def render_preview(self, data: mujoco.MjData, index: int, binning: int) -> np.ndarray:
        """Camera ``index``'s whole view binned ``binning`` x ``binning``: (H/b, W/b, 3) uint8.

        A low-resolution readout of the same camera (lens included), for finding
        where to look; pixel (i, j) covers the image's pixels b i .. b i + b - 1.
        Its noise (the camera's std) comes from a stream of its own, so the
        camera's images get the same noise with and without previews.  Counted
        as a render and as 1/b^2 of a frame's pixels.
        """
        camera = self._cameras[index]
        if camera.width % binning or camera.height % binning:
            raise ValueError(
                f"binning {binning} must divide the {camera.width}x{camera.height} image"
            )
        self.render_count += 1
        frame = self._previews[index]
        self._previews[index] += 1
        shot = imperfections.Shot(
            (self._seed, index, PREVIEW_STREAM), frame, (camera.width, camera.height), binning
        )
        return imperfections.finish(
            lambda rect: self._draw(data, index, rect, binning=binning), self._stages[index], shot
        )

    def render(self, data: mujoco.MjData, index: int, retake: bool = False) -> np.ndarray:
        """Render camera ``index`` (0 = Ca1, 1 = Ca2) from ``data``: (H, W, 3) uint8.

        ``retake``: the whole of the image just taken as a window (the same
        instant: the same noise); it is still a render and is counted.
        """
        return self._finish(data, index, None, retake)

    def render_window(
        self, data: mujoco.MjData, index: int, window: Window, retake: bool = False
    ) -> np.ndarray:
        """Render only ``window`` of camera ``index``: the full frame's crop, (h, w, 3) uint8.

        ``retake``: a window of the image just taken (the same instant: the same noise);
        it is still a render and is counted.
        """
        camera = self._cameras[index]
        if not (
            0 <= window.x0 < window.x1 <= camera.width
            and 0 <= window.y0 < window.y1 <= camera.height
        ):
            raise ValueError(
                f"window {window} is not inside the {camera.width}x{camera.height} image"
            )
        return self._finish(data, index, window, retake)

    def _finish(
        self, data: mujoco.MjData, index: int, window: Window | None, retake: bool
    ) -> np.ndarray:
        """Image or ``window`` of camera ``index``: drawn, then every imperfection applied."""
        self.render_count += 1
        if retake and self._taken[index] > 0:
            frame = self._taken[index] - 1
        else:
            frame = self._taken[index]
            self._taken[index] += 1
        camera = self._cameras[index]
        shot = imperfections.Shot((self._seed, index), frame, (camera.width, camera.height))
        return imperfections.finish(
            lambda rect: self._draw(data, index, rect), self._stages[index], shot, window
        )

    def close(self) -> None:
        """Give the OpenGL context back to the pool (closed if it was this renderer's own)."""
        if self._own:
            for key in [k for k in _POOL if isinstance(k, tuple) and k[0] == self._key]:
                _POOL.pop(key).close()


#: The noise stream of previews (``EyeRenderer.render_preview``), beside each camera's own.
PREVIEW_STREAM = 1_000_003
