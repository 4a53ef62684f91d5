"""N live heads advanced together as arrays (see :mod:`headsim.lockstep`)."""

from __future__ import annotations

import ctypes.util
from collections import OrderedDict, deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from mujoco import batch as mj_batch

from headsim.live.head import LiveConfig
from headsim.live.motors import MotorDriver, motor_joints
from headsim.live.paths import Path, Static
from headsim.sim import imperfections, names
from headsim.sim.gl_window import Window
from headsim.sim.model import HEAD_PREFIX, BuiltModel, build_model
from headsim.sim.settings import HeadSettings, SettingsError
from headsim.sim.textured_scene import RoomSpec

from .motors import VelocityMotors
from .opengl import EyeView, ViewRenderer

#: The pose arrays an eye image depends on, as ``mujoco.batch`` binds them (MjData's names).
POSE_FIELDS = ("geom_xpos", "geom_xmat", "cam_xpos", "cam_xmat", "light_xpos", "light_xdir")

#: The renderers lockstep heads draw through ("auto": chosen per device, :func:`_resolve`).
RENDERERS = ("auto", "opengl", "warp-cpu", "warp-cuda")
#: Compiled heads kept for reuse, by their settings (the least recently used goes first).
BUILDS_KEPT = 64
_CTRL = int(mujoco.mjtState.mjSTATE_CTRL)
_CTRL_AND_MOCAP = _CTRL | int(mujoco.mjtState.mjSTATE_MOCAP_POS)


@dataclass(frozen=True)
class Frames:
    """One capture of some heads, as arrays over them (row i: head ``heads[i]``).

    ``encoders_rad``: (neck yaw, neck pitch, eye motor), quantised as the live head's.
    ``truth_*``: for scoring and recording only (target NaN where there is none)."""

    heads: np.ndarray
    time_s: np.ndarray
    images: np.ndarray  # (m, 2, H, W, 3) uint8, Ca1 then Ca2
    encoders_rad: np.ndarray
    truth_target_world_m: np.ndarray
    truth_joints_rad: np.ndarray


@dataclass
class _Build:
    """One head's compiled model and what the loop reads of it."""

    settings: HeadSettings
    built: BuiltModel
    qadr: np.ndarray  # the motors' qpos addresses
    drive: tuple[tuple[int, ...], tuple[int, ...], tuple[float, ...]]  # actuator, motor, gear
    feed_velocity_s: np.ndarray  # per actuator of ``drive``: the driver's feed-forwards
    feed_acceleration_s2: np.ndarray
    low: np.ndarray
    high: np.ndarray
    home: int
    mocap: int  # the target's mocap index, -1 without one
    stages: tuple[imperfections.Stages, imperfections.Stages]


@dataclass
class _Stream:
    """A head's image streams: image k of camera i is finished with noise from
    (seed, i, k), as the classic renderer's (a head keeps them while its settings do)."""

    seed: int
    taken: list[int]


class LockstepHeads:
    """``n`` live heads of one scene advanced together.

    Every head has its own settings (cameras, mounts, tolerances, noise seed), target
    path, motor state, clock and image streams; they share one MuJoCo batch (physics, on
    the heads' own models where their settings differ) and one OpenGL context.
    ``config``: the live head's timing (no exposure or motion blur here).  ``target_body``:
    the mocap body each head's path moves.  ``prepare``: edits a freshly compiled model
    (before its motors are tuned).  ``supersample``: each image's supersampling (None:
    each head's ``render.supersample``, the classic renderer's images).  ``renderer``: one
    of :data:`RENDERERS`: ``"auto"`` takes MuJoCo Warp on a GPU where Warp finds one, else
    the classic OpenGL renderer on the CPU (faster there); ``"warp-cpu"`` runs the device
    path on Warp's CPU device (for tests).  :meth:`describe` says which runs.
    """

    def __init__(
        self,
        n: int,
        settings: HeadSettings,
        config: LiveConfig | None = None,
        *,
        scene: str = "default",
        room: RoomSpec | None = None,
        target_body: str | None = None,
        prepare: Callable[[mujoco.MjModel], None] | None = None,
        supersample: int | None = None,
        threads: int = 1,
        renderer: str = "auto",
    ) -> None:
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise SettingsError(f"n must be a whole number >= 1, got {n!r}")
        self.config = config or LiveConfig()
        if self.config.exposure_s > 0:
            raise SettingsError(
                "exposure_s: lockstep heads take instantaneous frames (0); "
                f"got {self.config.exposure_s}"
            )
        if supersample is not None and not (isinstance(supersample, int) and 1 <= supersample <= 8):
            raise SettingsError(f"supersample must be None or 1..8, got {supersample!r}")
        if renderer not in RENDERERS:
            raise SettingsError(f"renderer must be one of {', '.join(RENDERERS)}, got {renderer!r}")
        #: The renderer that runs: "opengl", "warp-cpu" or "warp-cuda".
        self.renderer = _resolve(renderer)
        self._warp: Any = None
        self.n = n
        self._scene, self._room, self._target = scene, room, target_body
        self._prepare, self._supersample = prepare, supersample
        self._builds: OrderedDict[HeadSettings, _Build] = OrderedDict()
        first = self._build(settings)
        self.dt = float(first.built.model.opt.timestep)
        self._heads = [first] * n
        self._streams = [_Stream(settings.seed, [0, 0]) for _ in range(n)]
        self.batch = mj_batch.Batch(first.built.model, n, nthread=threads, persistent=True)
        self.batch.set_models([first.built.model] * n)
        self._qpos = self.batch.bind("qpos")
        self._ctrl = self.batch.bind("ctrl")
        self._mocap_pos = self.batch.bind("mocap_pos")
        self._data = [mujoco.MjData(first.built.model) for _ in range(n)]
        # Bound before any call, so that the batch refreshes them after each.
        self._poses = {name: self.batch.bind(name) for name in POSE_FIELDS}
        limits = (self.config.neck_limits, self.config.neck_limits, self.config.eye_limits)
        self.motors = VelocityMotors(n, limits)
        self._drive = first.drive
        self._acts = np.array(first.drive[0], np.int64)
        self._motor_of = np.array(first.drive[1], np.int64)
        self._gears = np.array(first.drive[2])
        self._feed_v = np.tile(first.feed_velocity_s, (n, 1))
        self._feed_a = np.tile(first.feed_acceleration_s2, (n, 1))
        self.paths: list[Path | None] = [None] * n
        self.step_count = np.zeros(n, np.int64)
        self.frame_index = np.zeros(n, np.int64)
        self._queues: list[deque[tuple[float, np.ndarray]]] = [deque() for _ in range(n)]
        #: When each head's last frame ended (a latent command is due a latency after), s.
        self._last_end = np.zeros(n)
        self._renderer: ViewRenderer | None = None
        self._opengl_before_s = 0.0  # in renderers since replaced by larger ones
        #: Eye images drawn.
        self.images = 0

    # -- heads -------------------------------------------------------------------
    def _build(self, settings: HeadSettings) -> _Build:
        known = self._builds.get(settings)
        if known is not None:
            self._builds.move_to_end(settings)
            return known
        built = build_model(self._scene, settings, self._room)
        model = built.model
        if self._prepare is not None:
            self._prepare(model)
        home_name = names.HOME if settings.head.is_paper else HEAD_PREFIX + names.HOME
        home = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, home_name)
        data = mujoco.MjData(model)
        if home >= 0:
            mujoco.mj_resetDataKeyframe(model, data, home)
        mujoco.mj_forward(model, data)
        config = self.config
        limits = (config.neck_limits, config.neck_limits, config.eye_limits)
        # The classic live head's tuning, written into the model (its actuator gains).
        driver = MotorDriver(model, data, limits, config.servo_bandwidth_hz, built.names)
        joints = motor_joints(built.names)
        mocap = -1
        if self._target is not None:
            body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, self._target)
            mocap = int(model.body_mocapid[body]) if body >= 0 else -1
            if mocap < 0:
                raise SettingsError(f"{self._target!r} is not a movable (mocap) body in this scene")
        build = _Build(
            settings,
            built,
            np.array([int(model.joint(j).qposadr[0]) for j in joints]),
            (
                tuple(act for pairs in driver.feeds for act, _, _, _ in pairs),
                tuple(m for m, pairs in enumerate(driver.feeds) for _ in pairs),
                tuple(gear for pairs in driver.feeds for _, gear, _, _ in pairs),
            ),
            np.array([fv for pairs in driver.feeds for _, _, fv, _ in pairs]),
            np.array([fa for pairs in driver.feeds for _, _, _, fa in pairs]),
            np.array([float(model.joint(j).range[0]) for j in joints]),
            np.array([float(model.joint(j).range[1]) for j in joints]),
            home,
            mocap,
            (
                imperfections.prepare(settings.cameras[0], built.canvases[0]),
                imperfections.prepare(settings.cameras[1], built.canvases[1]),
            ),
        )
        self._builds[settings] = build
        while len(self._builds) > BUILDS_KEPT:
            self._builds.popitem(last=False)
        return build

    def poses(self) -> dict[str, np.ndarray]:
        """Every head's pose arrays a renderer reads (:data:`POSE_FIELDS`), rows per head,
        after its last step: what a device renderer uploads."""
        return dict(self._poses)

    def settings(self, head: int) -> HeadSettings:
        """Head ``head``'s settings."""
        return self._heads[head].settings

    def camera_names(self, head: int) -> tuple[str, str]:
        """Head ``head``'s eye cameras as compiled into its model (Ca1, Ca2)."""
        return self._heads[head].built.names.cameras

    def model(self, head: int) -> mujoco.MjModel:
        """Head ``head``'s compiled model (shared by heads of equal settings)."""
        return self._heads[head].built.model

    # -- episodes ----------------------------------------------------------------
    def reset(
        self,
        heads: Sequence[int] | np.ndarray,
        settings: Sequence[HeadSettings],
        paths: Sequence[Path | None],
        images: bool = True,
    ) -> Frames:
        """Start ``heads`` afresh at home with ``settings`` and target ``paths``, and take
        each one's frame 0.  A head whose settings change gets new image streams (as a
        classic simulator made for them); one whose settings stay keeps its own."""
        ids = np.asarray(heads, np.int64)
        changed = False
        for head, wanted in zip(ids, settings, strict=True):
            if wanted != self._heads[head].settings:
                build = self._build(wanted)
                if build.drive != self._drive:
                    raise SettingsError(
                        "lockstep heads must share their motors' actuators and gears "
                        "(one kind of head)"
                    )
                self._heads[head] = build
                self._feed_v[head] = build.feed_velocity_s
                self._feed_a[head] = build.feed_acceleration_s2
                self._streams[head] = _Stream(wanted.seed, [0, 0])
                changed = True
        if changed:
            self.batch.set_models([h.built.model for h in self._heads])
        homes = np.array([self._heads[h].home for h in ids])
        self.batch.reset(ids, keyframe=homes, stage=int(mujoco.mjtStage.mjSTAGE_NONE))
        self.step_count[ids] = 0
        self.frame_index[ids] = 0
        for head, path in zip(ids, paths, strict=True):
            self.paths[head] = path
            self._queues[head].clear()
        self._place_targets(ids)
        self.batch.forward(ids)
        qadr = np.stack([self._heads[h].qadr for h in ids])
        self.motors.sync(
            ids,
            np.take_along_axis(self._qpos[ids], qadr, axis=1),
            np.stack([self._heads[h].low for h in ids]),
            np.stack([self._heads[h].high for h in ids]),
        )
        self._write_ctrl(ids)
        return self.capture(ids, images)

    def _place_targets(self, ids: np.ndarray) -> None:
        for head in ids:
            build, path = self._heads[head], self.paths[head]
            if build.mocap >= 0 and path is not None:
                time_s = float(self.step_count[head]) * self.dt
                self._mocap_pos[head, build.mocap] = path.position(time_s)

    # -- commands ----------------------------------------------------------------
    def command_velocity(self, heads: Sequence[int] | np.ndarray, speeds_rad_s: np.ndarray) -> None:
        """Ramp each head's motors to ``speeds_rad_s`` (m, 3): at once without latency,
        else ``latency_frames`` periods after the head's last frame ended."""
        ids = np.asarray(heads, np.int64)
        speeds = np.asarray(speeds_rad_s, float)
        if self.config.latency_frames == 0:
            self.motors.set_speed(ids, speeds)
            return
        for head, speed in zip(ids, speeds, strict=True):
            self._queues[head].append((self._last_end[head] + self.config.latency_s, speed))

    # -- time --------------------------------------------------------------------
    def capture(self, heads: Sequence[int] | np.ndarray, images: bool = True) -> Frames:
        """Advance ``heads`` to their next frame and take it (both cameras of every one;
        with ``images=False`` none are drawn here, for a caller that renders the heads'
        :meth:`poses` itself, and ``Frames.images`` is empty)."""
        ids = np.asarray(heads, np.int64)
        period = self.config.period_s
        time_s = self.step_count[ids] * self.dt
        start = self.frame_index[ids] * period
        late = start < time_s - 1e-9  # time ran past a frame: take the next one due
        if late.any():
            self.frame_index[ids[late]] = np.ceil(time_s[late] / period - 1e-9).astype(np.int64)
            start = self.frame_index[ids] * period
        goal = np.round(start / self.dt).astype(np.int64)
        steps = goal - self.step_count[ids]
        for count in np.unique(steps):
            if count > 0:
                self._advance(ids[steps == count], int(count))
        truth_joints = np.take_along_axis(
            self._qpos[ids], np.stack([self._heads[h].qadr for h in ids]), axis=1
        )
        resolution = np.array([self._heads[h].settings.encoder_resolution_rad for h in ids])
        encoders = np.round(truth_joints / resolution[:, None]) * resolution[:, None]
        truth = np.full((len(ids), 3), np.nan)
        for row, (head, at) in enumerate(zip(ids, start, strict=True)):
            path = self.paths[head]
            if path is not None:
                truth[row] = path.position(float(at))
        frames = Frames(
            ids,
            goal * self.dt,
            self._render(ids) if images else np.empty((len(ids), 2, 0, 0, 3), np.uint8),
            encoders,
            truth,
            truth_joints,
        )
        self._last_end[ids] = np.maximum(start, self.step_count[ids] * self.dt)
        self.frame_index[ids] += 1
        return frames

    def _advance(self, ids: np.ndarray, nstep: int) -> None:
        """``nstep`` physics steps of ``ids``: the motors' references advanced in numpy,
        the physics in one batch rollout, the targets moved at every step."""
        nu = self.batch.model.nu
        moving = [row for row, head in enumerate(ids) if self._moves(head)]
        spec = _CTRL_AND_MOCAP if moving else _CTRL
        width = mujoco.mj_stateSize(self.batch.model, spec)
        refs, vels, accs = self.motors.ramp(ids, self._speeds(ids, nstep), self.dt)
        control = np.empty((len(ids), nstep, width))
        control[:, :, :nu] = self._ctrl[ids][:, None, :]
        control[:, :, self._acts] = self._drive_ctrl(ids, refs, vels, accs).transpose(1, 0, 2)
        if moving:
            control[:, :, nu:] = self._mocap_pos[ids].reshape(len(ids), 1, -1)
            for row in moving:
                head = ids[row]
                path, mocap = self.paths[head], self._heads[head].mocap
                assert path is not None
                column = nu + 3 * mocap
                for j in range(nstep):
                    at = float(self.step_count[head] + j) * self.dt
                    control[row, j, column : column + 3] = path.position(at)
        self.batch.rollout(nstep, control, control_spec=spec, record=(), ids=ids)
        self.step_count[ids] += nstep
        self._place_targets(ids)
        self.batch.forward(ids)

    def _speeds(self, ids: np.ndarray, nstep: int) -> np.ndarray:
        """The speed each motor of ``ids`` is commanded during each of the next ``nstep``
        steps (nstep, m, 3): a latent command takes over at the first step it is due."""
        now = self.motors.speed[ids]
        if not self.config.latency_frames:
            return np.broadcast_to(now, (nstep, *now.shape))
        speeds = np.empty((nstep, *now.shape))
        for j in range(nstep):
            for row, head in enumerate(ids):
                queue, at = self._queues[head], float(self.step_count[head] + j) * self.dt
                while queue and queue[0][0] <= at + 1e-12:
                    self.motors.set_speed(np.array([head]), queue.popleft()[1][None, :])
                    now[row] = self.motors.speed[head]
            speeds[j] = now
        return speeds

    def _moves(self, head: int) -> bool:
        path = self.paths[head]
        return path is not None and self._heads[head].mocap >= 0 and not isinstance(path, Static)

    def _drive_ctrl(
        self, ids: np.ndarray, ref: np.ndarray, vel: np.ndarray, acc: np.ndarray
    ) -> np.ndarray:
        """The driven actuators' controls from references (..., m, 3), as the classic
        driver writes them: gear * (ref + fv vel + fa acc), term for term."""
        m = self._motor_of
        return self._gears * (
            ref[..., m] + self._feed_v[ids] * vel[..., m] + self._feed_a[ids] * acc[..., m]
        )

    def _write_ctrl(self, ids: np.ndarray) -> None:
        """``ids``' driven actuators from their motors' references now."""
        motors = self.motors
        drive = self._drive_ctrl(ids, motors.ref[ids], motors.vel[ids], motors.acc[ids])
        self._ctrl[ids[:, None], self._acts] = drive

    # -- images ------------------------------------------------------------------
    def _render(self, ids: np.ndarray) -> np.ndarray:
        """Both eyes of every head in ``ids``, drawn through one context and finished from
        each head's own streams: (m, 2, H, W, 3) uint8."""
        canvases = self._draw_opengl(ids) if self._warp_device is None else self._cast(ids)
        images = []
        for row, head in enumerate(ids):
            build, stream = self._heads[head], self._streams[head]
            pair = []
            for index in range(2):
                camera = build.settings.cameras[index]
                shot = imperfections.Shot(
                    (stream.seed, index), stream.taken[index], (camera.width, camera.height)
                )
                stream.taken[index] += 1
                pair.append(
                    imperfections.finish(
                        _given(canvases[2 * row + index]), build.stages[index], shot
                    )
                )
            images.append(pair)
        self.images += 2 * len(ids)
        shapes = {image.shape for pair in images for image in pair}
        if len(shapes) != 1:
            raise SettingsError(f"lockstep heads must share one image size, got {sorted(shapes)}")
        return np.array(images, np.uint8)

    @property
    def _warp_device(self) -> str | None:
        return None if self.renderer == "opengl" else self.renderer.removeprefix("warp-")

    def _cast(self, ids: np.ndarray) -> list[np.ndarray]:
        """``ids``' pinhole canvases cast by MuJoCo Warp: every head in one call."""
        first = self._heads[0]
        if any(build is not first for build in self._heads):
            raise SettingsError(
                f"renderer {self.renderer!r}: heads on MuJoCo Warp share one head's settings "
                "(cameras, baseline, noise); allowed: randomise only the targets, or "
                "renderer='opengl'"
            )
        if self._warp is None:
            from headsim.lockstep.warp_eyes import WarpEyes

            sizes = {canvas.size for canvas in first.built.canvases}
            if len(sizes) != 1:
                raise SettingsError(
                    f"renderer {self.renderer!r}: both eyes' canvases must be one size, "
                    f"got {sorted(sizes)}"
                )
            k = (
                first.settings.render.supersample
                if self._supersample is None
                else self._supersample
            )
            self._warp = WarpEyes(
                first.built.model,
                first.built.names.cameras,
                sizes.pop(),
                self.n,
                device=self._warp_device or "cpu",
                samples_per_pixel=k,
            )
        self._warp.cast(self.poses())
        cast = self._warp.images()
        return [cast[head, index] for head in ids for index in range(2)]

    def _draw_opengl(self, ids: np.ndarray) -> list[np.ndarray]:
        """``ids``' pinhole canvases drawn in turn through one OpenGL context."""
        views = []
        for head in ids:
            build = self._heads[head]
            data = self.batch.get_data(int(head), self._data[head])
            k = (
                build.settings.render.supersample
                if self._supersample is None
                else self._supersample
            )
            for camera, canvas in zip(build.built.names.cameras, build.built.canvases, strict=True):
                views.append(EyeView(build.built.model, data, camera, canvas.size, k))
        return self._renderer_for(views).draw(views)

    def _renderer_for(self, views: Sequence[EyeView]) -> ViewRenderer:
        need = (
            max(v.supersample * v.canvas_px[0] for v in views),
            max(v.supersample * v.canvas_px[1] for v in views),
        )
        renderer = self._renderer
        if renderer is not None and (
            renderer.largest_px[0] < need[0] or renderer.largest_px[1] < need[1]
        ):
            need = (max(need[0], renderer.largest_px[0]), max(need[1], renderer.largest_px[1]))
            self._opengl_before_s += renderer.opengl_cpu_s
            renderer.close()
            renderer = None
        if renderer is None:
            renderer = ViewRenderer(views[0].model, need)
            self._renderer = renderer
        return renderer

    @property
    def opengl_cpu_s(self) -> float:
        """CPU seconds spent in OpenGL's draws and reads so far (the renderer's)."""
        now = 0.0 if self._renderer is None else self._renderer.opengl_cpu_s
        return self._opengl_before_s + now

    def describe(self) -> str:
        """The renderer, in words."""
        if self._warp_device is None:
            return f"classic OpenGL renderer on the CPU: {self.n} heads, one context"
        return f"MuJoCo Warp on {self._warp_device}: {self.n} heads x 2 cameras in one call"

    def close(self) -> None:
        """Free the OpenGL context."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def _resolve(renderer: str) -> str:
    """The renderer ``renderer`` names here ("auto": Warp on a GPU if Warp finds one)."""
    if renderer == "auto":
        if ctypes.util.find_library("cuda") is None:  # no driver: no GPU, and no Warp import
            return "opengl"
        from headsim.sim.batch import cuda_available

        return "warp-cuda" if cuda_available() else "opengl"
    if renderer == "warp-cuda":
        from headsim.sim.batch import check_device

        check_device("cuda")  # a one-line refusal where Warp finds no GPU
    return renderer


def _given(canvas: np.ndarray) -> Callable[[Window | None], np.ndarray]:
    """A draw that hands over a canvas already drawn (a whole frame's)."""

    def draw(_rect: Window | None) -> np.ndarray:
        return canvas

    return draw


__all__ = ["BUILDS_KEPT", "POSE_FIELDS", "RENDERERS", "Frames", "LockstepHeads"]
