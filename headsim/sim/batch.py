"""Eye images of many worlds at once through MuJoCo Warp's ray caster, and the one adapter
to ``mujoco_warp`` and ``warp`` (the ``batch`` extra: ``pip install 'headsim[batch]'``).

:class:`BatchRenderer` casts both eye cameras of ``nworld`` copies of one head at given
joint positions in one Warp call per camera and finishes each image as the classic
renderer finishes its own (:func:`headsim.sim.imperfections.finish`: the lens by remap,
the camera's noise from a stream of its own).  Anti-aliasing: ``samples_per_pixel`` x
``samples_per_pixel`` rays per pixel on a regular grid, averaged (the classic path's
supersampling, without its MSAA); each world casts from its own eye's pose and
intrinsics in one camera slot, through Warp's per-world camera parameters.
Heads that move, servo and measure together are :mod:`headsim.lockstep`'s (its device
path reaches Warp through :func:`check_device`).  Warp is imported only when asked
for; it runs on the CPU by default, on a GPU with ``device="cuda"`` where it finds one.
"""

from __future__ import annotations

import contextlib
import ctypes.util
import hashlib
import importlib
import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from types import ModuleType

import cv2
import mujoco
import numpy as np

from headsim.errors import BadInput
from headsim.sim import imperfections
from headsim.sim.simulator import HeadSim

#: The devices Warp runs on here.
DEVICES = ("cpu", "cuda")
#: The noise stream of :class:`BatchRenderer`'s images, apart from the classic renderer's.
BATCH_STREAM = 0xBA7C
#: The most sub-pixel samples per axis a Warp cast takes.
MAX_SAMPLES_PER_PIXEL = 8


class BatchError(BadInput, ValueError):
    """A batch session cannot be made or run as asked: what is wrong and what is allowed."""


@dataclass(frozen=True)
class _Warp:
    wp: ModuleType
    mjw: ModuleType


@contextlib.contextmanager
def _stderr_closed() -> Iterator[None]:
    """Native writes to file descriptor 2 go to /dev/null while inside."""
    saved = os.dup(2)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _start_warp(wp: ModuleType) -> None:
    """Start Warp's runtime; quietly where this machine has no CUDA driver at all.

    Warp's native start-up prints "Could not find or load the NVIDIA CUDA driver"
    with ``fprintf`` whenever ``libcuda`` is missing, which on a CPU-only machine
    says nothing the user asked about.  Only then is its stderr closed, and only
    around the start; with a driver present every message goes through.
    """
    if ctypes.util.find_library("cuda") is not None:
        wp.init()
        return
    with _stderr_closed():
        wp.init()


def _warp() -> _Warp:
    try:
        wp = importlib.import_module("warp")
        # Warnings only (not each kernel module's load time), before mujoco_warp starts Warp.
        wp.config.log_level = wp.LOG_WARNING
        _start_warp(wp)
        mjw = importlib.import_module("mujoco_warp")
    except ImportError as err:
        raise BatchError(
            f"the batch back-end needs MuJoCo Warp ({err.name} is not installed); "
            "allowed: pip install 'headsim[batch]'"
        ) from None
    return _Warp(wp, mjw)


def cuda_available() -> bool:
    """Whether Warp finds a CUDA device here (False without the batch extra)."""
    try:
        return bool(_warp().wp.is_cuda_available())
    except BatchError:
        return False


def check_device(device: str) -> _Warp:
    """Warp, once ``device`` is known to run here; else a :class:`BatchError` saying why."""
    if device not in DEVICES:
        raise BatchError(f"device must be one of {', '.join(DEVICES)}, got {device!r}")
    warp = _warp()
    if device == "cuda" and not warp.wp.is_cuda_available():
        raise BatchError("device 'cuda': Warp finds no CUDA device here; allowed: cpu")
    return warp


def _check_samples(samples_per_pixel: int | None) -> None:
    if samples_per_pixel is None:
        return
    if not (
        isinstance(samples_per_pixel, int)
        and not isinstance(samples_per_pixel, bool)
        and 1 <= samples_per_pixel <= MAX_SAMPLES_PER_PIXEL
    ):
        raise BatchError(
            f"samples_per_pixel must be a whole number from 1 to {MAX_SAMPLES_PER_PIXEL}, "
            f"got {samples_per_pixel!r}"
        )


# -- what a world's image depends on ---------------------------------------------------

#: What Warp reads of a model beside the poses: geoms, materials, textures, meshes, lights.
_SCENE_ARRAYS = (
    "geom_type",
    "geom_size",
    "geom_rgba",
    "geom_matid",
    "geom_dataid",
    "geom_group",
    "mat_rgba",
    "mat_texid",
    "mat_texrepeat",
    "mat_emission",
    "mat_specular",
    "mat_shininess",
    "mesh_vert",
    "mesh_face",
    "tex_data",
    "light_type",
    "light_castshadow",
    "light_active",
    "light_ambient",
    "light_diffuse",
    "light_specular",
    "light_attenuation",
    "light_cutoff",
    "light_exponent",
    "cam_projection",
)

#: The sensor every Warp scene's cameras cast from (MuJoCo's ``cam_sensorsize``, which Warp
#: holds per camera, not per world): each world's own sensor and intrinsics are expressed
#: on it (:func:`window_intrinsic`), so heads of other sensors share a call.
CAST_SENSOR = np.array([1.0, 1.0])
#: The camera slot every world's image is cast in (the model's first camera): Warp renders
#: only it; each world's own eye camera is put there.
CAST_CAMERA = 0


def _scene_digest(model: mujoco.MjModel) -> str:
    digest = hashlib.sha1()
    for name in _SCENE_ARRAYS:
        digest.update(name.encode())
        digest.update(np.ascontiguousarray(getattr(model, name)).tobytes())
    vis = model.vis
    digest.update(
        np.array(
            [vis.map.znear, vis.map.zfar, model.stat.extent, *vis.headlight.ambient],
            dtype=float,
        ).tobytes()
    )
    return digest.hexdigest()


@dataclass(frozen=True)
class _Pose:
    """What the ray caster reads of one world's state (MjData after forward kinematics)."""

    geom_xpos: np.ndarray
    geom_xmat: np.ndarray
    cam_xpos: np.ndarray
    cam_xmat: np.ndarray
    light_xpos: np.ndarray
    light_xdir: np.ndarray

    @classmethod
    def of(cls, model: mujoco.MjModel, data: mujoco.MjData) -> _Pose:
        return cls(
            data.geom_xpos.copy(),
            data.geom_xmat.reshape(model.ngeom, 3, 3).copy(),
            data.cam_xpos.copy(),
            data.cam_xmat.reshape(model.ncam, 3, 3).copy(),
            data.light_xpos.copy(),
            data.light_xdir.copy(),
        )


def _sensor_for(sensor_m: np.ndarray, size: tuple[int, int]) -> tuple[float, float]:
    """The sensor Warp casts an image of ``size`` from: cut to the image's aspect."""
    width_m, height_m = float(sensor_m[0]), float(sensor_m[1])
    aspect = size[0] / size[1]
    if aspect > width_m / height_m:
        return width_m, width_m / aspect
    if aspect < width_m / height_m:
        return height_m * aspect, height_m
    return width_m, height_m


def window_intrinsic(
    intrinsic_m: np.ndarray,
    sensor_m: np.ndarray,
    canvas_size: tuple[int, int],
    corners_px: tuple[float, float, float, float],
    size: tuple[int, int],
    cast_sensor: np.ndarray | None = None,
) -> np.ndarray:
    """The camera (fx, fy, cx, cy, MuJoCo's ``cam_intrinsic``, in the units of the
    sensor) whose image of ``size`` px on ``cast_sensor`` (default: the camera's own
    ``sensor_m``) covers the canvas's rectangle ``corners_px`` (x0, y0, x1, y1, in the
    canvas's pixels): the same rays as the canvas's pixels there, fewer to cast."""
    fx, fy, cx, cy = (float(v) for v in intrinsic_m)
    width, height = canvas_size
    sensor_w, sensor_h = _sensor_for(sensor_m, canvas_size)
    left, right = -(sensor_w / 2 - cx) / fx, (sensor_w / 2 + cx) / fx  # at unit depth
    top, bottom = (sensor_h / 2 - cy) / fy, -(sensor_h / 2 + cy) / fy
    x0, y0, x1, y1 = corners_px
    window_left = left + (right - left) * x0 / width
    window_right = left + (right - left) * x1 / width
    window_top = top + (bottom - top) * y0 / height
    window_bottom = top + (bottom - top) * y1 / height
    sensor_w, sensor_h = _sensor_for(sensor_m if cast_sensor is None else cast_sensor, size)
    fx_w = sensor_w / (window_right - window_left)
    fy_w = sensor_h / (window_top - window_bottom)
    cx_w = sensor_w / 2 + window_left * fx_w
    cy_w = sensor_h / 2 - window_top * fy_w
    return np.array([fx_w, fy_w, cx_w, cy_w], np.float32)


@dataclass(frozen=True)
class _Kind:
    """What worlds rendered together share: the scene, the image's size, the samples (each
    world casts from its own camera, pose and intrinsics, in the scene's camera slot)."""

    digest: str
    size: tuple[int, int]
    samples: int


@dataclass(frozen=True)
class _Request:
    model: mujoco.MjModel
    kind: _Kind
    pose: _Pose
    camera: int
    fovy: float
    intrinsic: np.ndarray
    keep: tuple[int, int]


class _Scene:
    """One Warp model, data and render context for up to ``nworld`` worlds of one kind.

    Rays are cast one per sub-pixel sample, on a grid ``samples`` times finer than the
    image, from each world's own camera parameters (focal length, principal point); each
    pixel is its samples' mean.  This is the classic renderer's supersampling, and lets
    worlds whose cameras differ share one call at any number of samples (Warp's own
    sub-pixel samples need rays precomputed for one camera)."""

    def __init__(
        self, warp: _Warp, device: str, model: mujoco.MjModel, kind: _Kind, nworld: int
    ) -> None:
        wp, mjw = warp.wp, warp.mjw
        self._warp, self._device, self.nworld, self.kind = warp, device, nworld, kind
        width, height = kind.size
        with wp.ScopedDevice(device):
            self._m = mjw.put_model(model)
            self._d = mjw.put_data(model, mujoco.MjData(model), nworld=nworld)
            self._rc = mjw.create_render_context(
                model,
                nworld=nworld,
                cam_res=[(width * kind.samples, height * kind.samples)],
                render_rgb=True,
                render_depth=False,
                cam_active=[CAST_CAMERA],
                use_precomputed_rays=False,
                deterministic=True,
            )
            self._m.cam_sensorsize = wp.array(
                np.tile(CAST_SENSOR, (model.ncam, 1)).astype(np.float32), dtype=wp.vec2
            )
        self._fovy = np.tile(model.cam_fovy.astype(np.float32), (nworld, 1))
        self._intrinsic = np.tile(model.cam_intrinsic.astype(np.float32), (nworld, 1, 1))

    def render(self, requests: Sequence[_Request]) -> list[np.ndarray]:
        """Each request's pinhole canvas, uint8 (h, w, 3)."""
        wp, mjw = self._warp.wp, self._warp.mjw
        n = len(requests)
        rows = [requests[min(i, n - 1)] for i in range(self.nworld)]  # idle worlds repeat

        def stacked(name: str) -> np.ndarray:
            return np.stack([getattr(r.pose, name) for r in rows]).astype(np.float32)

        d, slot = self._d, CAST_CAMERA
        cam_xpos, cam_xmat = stacked("cam_xpos"), stacked("cam_xmat")
        for i, r in enumerate(rows):  # each world's own camera, in the scene's one slot
            cam_xpos[i, slot] = r.pose.cam_xpos[r.camera]
            cam_xmat[i, slot] = r.pose.cam_xmat[r.camera]
            self._fovy[i, slot] = r.fovy
            self._intrinsic[i, slot] = r.intrinsic
        with wp.ScopedDevice(self._device):
            d.geom_xpos.assign(stacked("geom_xpos"))
            d.geom_xmat.assign(stacked("geom_xmat"))
            d.cam_xpos.assign(cam_xpos)
            d.cam_xmat.assign(cam_xmat)
            if d.light_xpos.shape[1]:
                d.light_xpos.assign(stacked("light_xpos"))
                d.light_xdir.assign(stacked("light_xdir"))
            self._m.cam_fovy = wp.array(self._fovy, dtype=float)
            self._m.cam_intrinsic = wp.array(self._intrinsic, dtype=wp.vec4)
            mjw.refit_bvh(self._m, d, self._rc)
            mjw.render(self._m, d, self._rc)
            packed = self._rc.rgb_data.numpy()[:n]  # ABGR in a uint32 per ray, one camera
        width, height = self.kind.size
        s = self.kind.samples
        bgra = packed.view(np.uint8).reshape(n, height * s, width * s, 4)
        images = []
        for world, request in zip(bgra, requests, strict=False):
            keep_w, keep_h = request.keep
            rgb = cv2.cvtColor(world[: keep_h * s, : keep_w * s], cv2.COLOR_BGRA2RGB)
            if s > 1:  # each pixel the mean of its s x s samples (an exact area mean)
                rgb = cv2.resize(rgb, (keep_w, keep_h), interpolation=cv2.INTER_AREA)
            images.append(rgb)
        return images


class _Caster:
    """Pinhole canvases of many worlds cast by MuJoCo Warp: one call per kind of world
    (scene, size, samples), on Warp scenes kept for reuse.  ``device``: ``"cpu"`` or
    ``"cuda"``; ``samples_per_pixel``: sub-pixel samples per axis (None: the caller's)."""

    def __init__(self, device: str = "cpu", samples_per_pixel: int | None = None) -> None:
        self._warp = check_device(device)
        _check_samples(samples_per_pixel)
        self.device = device
        self.samples_per_pixel = samples_per_pixel
        self._scenes: dict[tuple[_Kind, int], _Scene] = {}
        self._digests: dict[int, tuple[mujoco.MjModel, str]] = {}

    def cast(
        self,
        model: mujoco.MjModel,
        data: Sequence[mujoco.MjData],
        camera: int,
        size: tuple[int, int],
        supersample: int = 1,
    ) -> list[np.ndarray]:
        """Camera ``camera``'s pinhole canvas of ``size`` in each of ``data`` (one model's
        worlds), uint8 (h, w, 3), in one Warp call."""
        sensor = model.cam_sensorsize[camera]
        if sensor[1] <= 0:
            raise BatchError(
                f"camera {camera} has no sensor size: the batch renderer casts from a camera's "
                "intrinsics (MJCF sensorsize and focal or focalpixel)"
            )
        samples = self.samples_per_pixel or supersample
        corners = (0.0, 0.0, float(size[0]), float(size[1]))
        intrinsic = window_intrinsic(
            model.cam_intrinsic[camera], sensor, size, corners, size, CAST_SENSOR
        )
        kind = _Kind(self._digest(model), size, samples)
        fovy = float(model.cam_fovy[camera])
        requests = [
            _Request(model, kind, _Pose.of(model, d), int(camera), fovy, intrinsic, size)
            for d in data
        ]
        nworld = 1 << max(len(requests) - 1, 0).bit_length()
        scene = self._scenes.get((kind, nworld))
        if scene is None:
            scene = _Scene(self._warp, self.device, model, kind, nworld)
            self._scenes[(kind, nworld)] = scene
        return scene.render(requests)

    def _digest(self, model: mujoco.MjModel) -> str:
        known = self._digests.get(id(model))
        if known is None or known[0] is not model:
            known = (model, _scene_digest(model))
            self._digests[id(model)] = known
        return known[1]


class BatchRenderer:
    """Both eye cameras of ``nworld`` copies of ``sim``'s head and scene at given joint
    positions, for comparisons with the classic renderer.

    ``render(qpos)`` takes each world's joint positions, (nworld, nq), and returns
    (nworld, 2, height, width, 3) uint8 images, camera Ca1 then Ca2: the lens by remap and
    noise from each world's own stream ``(seed, BATCH_STREAM, world, camera)``.
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
        self._caster = _Caster(device, samples_per_pixel)
        self.device, self.nworld = device, nworld
        self.model: mujoco.MjModel = sim.model
        self._cameras = [int(self.model.camera(name).id) for name in sim.names.cameras]
        self._canvases = sim.built.canvases
        self._stages = tuple(
            imperfections.prepare(camera, canvas)
            for camera, canvas in zip(sim.settings.cameras, self._canvases, strict=True)
        )
        self._sizes = tuple((c.width, c.height) for c in sim.settings.cameras)
        self._seed = sim.settings.seed if seed is None else seed
        self._frame = 0

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
        worlds = []
        for row in q:
            data = mujoco.MjData(self.model)
            data.qpos[:] = row
            mujoco.mj_kinematics(self.model, data)
            mujoco.mj_camlight(self.model, data)
            worlds.append(data)
        images = [
            self._caster.cast(self.model, worlds, self._cameras[c], self._canvases[c].size)
            for c in range(2)
        ]
        out = np.stack(
            [
                np.stack([self._finish(images[c][w], c, w) for c in range(2)])
                for w in range(self.nworld)
            ]
        )
        self._frame += 1
        return out

    def _finish(self, image: np.ndarray, camera: int, world: int) -> np.ndarray:
        shot = imperfections.Shot(
            (self._seed, BATCH_STREAM, world, camera), self._frame, self._sizes[camera]
        )
        return imperfections.finish(lambda _: image, self._stages[camera], shot)


__all__ = [
    "DEVICES",
    "BatchError",
    "BatchRenderer",
    "check_device",
    "cuda_available",
]
