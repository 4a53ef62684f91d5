"""N heads at rest, advanced together: the classic simulator's kinematic settling over arrays.

The procedures measure a head at rest (:class:`~headsim.sim.simulator.HeadSim`'s default
``settle_mode = "kinematic"``): a command puts each joint where it truly settles (the
head's joint errors: backlash by the side it came from, count error) and forward
kinematics follows.  :class:`SettledHeads` does that for ``n`` heads of one settings in one
``mujoco.batch`` call, reads their encoders as the classic simulator reads them, and draws
one camera of many heads through one OpenGL context
(:class:`~headsim.lockstep.opengl.ViewRenderer`, full frames, the classic renderer's
pixels), each finished from the head's own noise stream.  Each head holds its own scene:
its own targets placed where it measures them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np
from mujoco import batch as mj_batch

from headsim.geometry.transforms import homogeneous, invert_transform
from headsim.sim import imperfections, names
from headsim.sim.gl_window import Window
from headsim.sim.heads import eye_motor_range
from headsim.sim.joints import Commands, true_targets
from headsim.sim.model import HEAD_PREFIX, BuiltModel, build_model
from headsim.sim.render import EyeRenderer, context_key
from headsim.sim.settings import HeadSettings, SettingsError

from .heads import _given
from .opengl import EyeView, ViewRenderer

#: The scene settled heads stand in unless told otherwise (the default one: no room).
DEFAULT_SCENE = "default"


class SettledHeads:
    """Heads at rest in ``scene``, one per entry of ``settings`` (each its own cameras,
    tolerances, noise; one kind of head); the eye motor commanded in whole encoder steps
    (the neck stays home).  Image k of camera c of head i carries noise from the stream
    ((seed, i), c, k): each head's own, apart from the classic simulator's."""

    def __init__(
        self,
        settings: Sequence[HeadSettings],
        scene: str = DEFAULT_SCENE,
        built: Sequence[BuiltModel] = (),
    ) -> None:
        """``built``: each head's model of ``scene``, already built (empty: built here); a
        lens's canvas costs about 30 ms to make."""
        if not settings:
            raise SettingsError("settled lockstep heads need at least one head's settings")
        self.n = len(settings)
        self.settings = list(settings)
        builds: dict[HeadSettings, BuiltModel] = {}
        given: Sequence[BuiltModel | None] = built or [None] * self.n
        for s, model in zip(settings, given, strict=True):
            if s not in builds:
                builds[s] = model if model is not None else build_model(scene, s)
        self.built = [builds[s] for s in settings]
        first = self.built[0]
        self.names = mapping = first.names
        if mapping.independent or mapping.version is not None:
            raise SettingsError(
                "settled lockstep heads drive one eye motor (coupled eyes); "
                "allowed: a head whose eyes share one motor"
            )
        if len({b.names for b in builds.values()}) != 1:
            raise SettingsError("settled lockstep heads must be one kind of head")
        model = first.model
        home_name = names.HOME if settings[0].head.is_paper else HEAD_PREFIX + names.HOME
        homes = [mujoco.mj_name2id(b.model, mujoco.mjtObj.mjOBJ_KEY, home_name) for b in self.built]
        self.batch = mj_batch.Batch(model, self.n, nthread=1, persistent=True)
        if len(builds) > 1:
            self.batch.set_models([b.model for b in self.built])
        self.batch.reset(keyframe=np.array(homes))
        self._qpos = self.batch.bind("qpos")
        self._mocap_pos = self.batch.bind("mocap_pos")
        # The motors HeadSim settles, and the joints each one moves (Ca2's eye with Ca1's).
        neck = (("neck_yaw", mapping.neck_yaw), ("neck_pitch", mapping.neck_pitch))
        self._motors = (*(motor for motor, joint in neck if joint is not None), "eye")
        joints = [
            j
            for j in (mapping.neck_yaw, mapping.neck_pitch, mapping.left_eye, mapping.right_eye)
            if j is not None
        ]
        self._joints = np.array([int(model.joint(j).qposadr[0]) for j in joints])
        self._eyes = self._joints[-2:]
        self._data = [mujoco.MjData(b.model) for b in self.built]
        self._commands = [Commands() for _ in range(self.n)]
        #: Each head's encoder resolution, rad.
        self.resolution_rad = np.array([s.encoder_resolution_rad for s in settings])
        ranges = set()
        for b, resolution in zip(self.built, self.resolution_rad, strict=True):
            low, high = eye_motor_range(b.model, mapping)
            ranges.add((math.ceil(low / resolution), math.floor(high / resolution)))
        if len(ranges) != 1:
            raise SettingsError(f"settled lockstep heads must share one eye range, got {ranges}")
        sizes = {(c.width, c.height) for s in settings for c in s.cameras}
        if len(sizes) != 1:
            raise SettingsError(f"settled lockstep heads must share one image size, got {sizes}")
        #: Every camera's image size (width, height), px.
        self.image_size_px: tuple[int, int] = sizes.pop()
        #: The eye motor's range, whole encoder steps.
        self.step_range: tuple[int, int] = ranges.pop()
        stages: dict[HeadSettings, tuple[imperfections.Stages, imperfections.Stages]] = {
            s: (
                imperfections.prepare(s.cameras[0], b.canvases[0]),
                imperfections.prepare(s.cameras[1], b.canvases[1]),
            )
            for s, b in builds.items()
        }
        self._stages = [stages[s] for s in settings]
        self._scene = scene
        # Previews through the classic renderer itself (its binned camera), one a build.
        self._previewers: dict[int, EyeRenderer] = {}
        self._taken = np.zeros((self.n, 2), np.int64)
        self._renderer: ViewRenderer | None = None
        #: Eye images drawn, and the heads' kinematic updates.
        self.images = 0
        self.settles = 0

    def gain_bound(self, head: int, camera: int) -> float:
        """A bound on camera ``camera``'s image motion per eye step of head ``head``, px:
        1.5 x its focal length times the encoder step (where a probe's window is placed;
        a window that misses costs a full frame, never another answer)."""
        return 1.5 * self.settings[head].cameras[camera - 1].kx * float(self.resolution_rad[head])

    # -- the scene ---------------------------------------------------------------
    def place(self, head: int, body: str, position_world_m: np.ndarray) -> None:
        """Put mocap body ``body`` of head ``head``'s scene at ``position_world_m``."""
        model = self.built[head].model
        body_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
        mocap = int(model.body_mocapid[body_id]) if body_id >= 0 else -1
        if mocap < 0:
            raise SettingsError(f"{body!r} is not a movable (mocap) body in this scene")
        self._mocap_pos[head, mocap] = position_world_m
        self.batch.forward(np.array([head]))

    def head_from_world(self, head: int) -> np.ndarray:
        """Head ``head``'s H from W, 4 x 4 (for scoring only)."""
        data = self.batch.get_data(head, self._data[head])
        body = data.body(self.names.head_body)
        return invert_transform(homogeneous(body.xmat.reshape(3, 3), body.xpos))

    # -- motors and encoders -----------------------------------------------------
    def command_eye_steps(self, heads: np.ndarray, steps: np.ndarray) -> None:
        """Command ``heads``' eye motors to ``steps`` and settle every motor as the classic
        simulator does (each joint where it truly settles: the neck's too), in one batch call."""
        ids = np.asarray(heads, np.int64)
        if ids.size == 0:
            return
        angles = np.empty((len(ids), len(self._joints)))
        for row, (head, step) in enumerate(zip(ids, steps, strict=True)):
            commands = self._commands[head]
            angle = int(step) * float(self.resolution_rad[head])
            if angle != commands.eye:
                commands.approach["eye"] = 1.0 if angle > commands.eye else -1.0
            commands.eye = angle
            true = true_targets(self.settings[head], commands, self._motors)
            # Coupled: Ca2's eye follows the one motor.
            angles[row] = [true[m] for m in self._motors] + [true["eye"]]
        self._qpos[ids[:, None], self._joints] = angles
        self.batch.forward(ids)
        self.settles += len(ids)

    def eye_steps(self, heads: Sequence[int] | np.ndarray) -> np.ndarray:
        """``heads``' eye encoders, whole steps: the command with joint errors (they lie
        beyond the motor's shaft), else the joint, as the classic simulator reads them."""
        ids = np.asarray(heads, np.int64)
        joint = self._qpos[ids, self._eyes[0]]
        read = np.array(
            [
                self._commands[h].eye if self.settings[h].joint_errors else joint[row]
                for row, h in enumerate(ids)
            ]
        )
        return np.round(read / self.resolution_rad[ids]).astype(np.int64)

    # -- images ------------------------------------------------------------------
    def render(
        self,
        heads: Sequence[int] | np.ndarray,
        camera: int,
        windows: Sequence[Window | None] | None = None,
    ) -> list[np.ndarray]:
        """Camera ``camera`` (1 or 2) of each of ``heads``: (H, W, 3) uint8 each, drawn
        through one context, each finished with its head's own noise; where ``windows``
        gives one, only that window of the frame (its crop, (h, w, 3))."""
        ids = np.asarray(heads, np.int64)
        wanted = [None] * len(ids) if windows is None else list(windows)
        index = camera - 1
        views = []
        for h in ids:
            built, k = self.built[h], self.settings[h].render.supersample
            data = self.batch.get_data(int(h), self._data[h])
            views.append(
                EyeView(
                    built.model, data, built.names.cameras[index], built.canvases[index].size, k
                )
            )
        if not views:
            return []
        need = (
            max(v.supersample * v.canvas_px[0] for v in views),
            max(v.supersample * v.canvas_px[1] for v in views),
        )
        renderer = self._renderer
        if renderer is not None and (
            renderer.largest_px[0] < need[0] or renderer.largest_px[1] < need[1]
        ):
            renderer.close()
            renderer = None
        if renderer is None:
            renderer = self._renderer = ViewRenderer(views[0].model, need)
        whole = [row for row, window in enumerate(wanted) if window is None]
        frames = dict(zip(whole, renderer.draw([views[row] for row in whole]), strict=True))
        images = []
        for row, head in enumerate(ids):
            camera_settings = self.settings[head].cameras[index]
            size = (camera_settings.width, camera_settings.height)
            shot = imperfections.Shot(
                (self.settings[head].seed, int(head)), int(self._taken[head, index]), size
            )
            self._taken[head, index] += 1
            stages, window = self._stages[head][index], wanted[row]
            if window is None:
                images.append(imperfections.finish(_given(frames[row]), stages, shot))
                continue

            def draw(rect: Window | None, view: EyeView = views[row]) -> np.ndarray:
                if rect is None or (rect.width, rect.height) == view.canvas_px:
                    return renderer.draw([view])[0]
                return renderer.draw_window(view, rect)

            images.append(imperfections.finish(draw, stages, shot, window))
        self.images += len(images)
        return images

    def preview(self, head: int, camera: int, binning: int) -> np.ndarray:
        """Camera ``camera``'s whole view of head ``head`` binned ``binning`` x ``binning``:
        the classic renderer's preview (:meth:`EyeRenderer.render_preview`), (H/b, W/b, 3)."""
        built, settings = self.built[head], self.settings[head]
        renderer = self._previewers.get(id(built))
        if renderer is None:
            renderer = EyeRenderer(
                built.model,
                settings.cameras,
                built.canvases,
                seed=settings.seed,
                key=context_key(self._scene, built.model),
                supersample=settings.render.supersample,
                camera_names=built.names.cameras,
            )
            self._previewers[id(built)] = renderer
        data = self.batch.get_data(int(head), self._data[head])
        self.images += 1
        return renderer.render_preview(data, camera - 1, binning)

    @property
    def opengl_cpu_s(self) -> float:
        """CPU seconds spent in OpenGL's draws and reads so far."""
        return 0.0 if self._renderer is None else self._renderer.opengl_cpu_s

    def close(self) -> None:
        """Free the OpenGL context."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __enter__(self) -> SettledHeads:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ = ["DEFAULT_SCENE", "SettledHeads"]
