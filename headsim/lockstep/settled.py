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
from headsim.sim.heads import eye_motor_range
from headsim.sim.joints import Commands, true_targets
from headsim.sim.model import HEAD_PREFIX, build_model
from headsim.sim.settings import HeadSettings, SettingsError

from .heads import _given
from .opengl import EyeView, ViewRenderer


class SettledHeads:
    """``n`` heads of ``settings`` at rest in ``scene``; the eye motor commanded in whole
    encoder steps (the neck stays home).  Image k of camera c of head i carries noise from
    the stream ((seed, i), c, k): each head's own, apart from the classic simulator's."""

    def __init__(self, n: int, settings: HeadSettings, scene: str = "default") -> None:
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise SettingsError(f"n must be a whole number >= 1, got {n!r}")
        if len({(c.width, c.height) for c in settings.cameras}) != 1:
            raise SettingsError("lockstep heads need both cameras of one image size")
        self.n, self.settings = n, settings
        self.built = build_model(scene, settings)
        self.model = model = self.built.model
        self.names = mapping = self.built.names
        if mapping.independent or mapping.version is not None:
            raise SettingsError(
                "settled lockstep heads drive one eye motor (coupled eyes); "
                "allowed: a head whose eyes share one motor"
            )
        home_name = names.HOME if settings.head.is_paper else HEAD_PREFIX + names.HOME
        home = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, home_name)
        self.batch = mj_batch.Batch(model, n, nthread=1, persistent=True)
        self.batch.reset(keyframe=home)
        self._qpos = self.batch.bind("qpos")
        self._mocap_pos = self.batch.bind("mocap_pos")
        self._eyes = np.array(
            [int(model.joint(j).qposadr[0]) for j in (mapping.left_eye, mapping.right_eye)]
        )
        self._data = [mujoco.MjData(model) for _ in range(n)]
        self._commands = [Commands() for _ in range(n)]
        self.resolution_rad = settings.encoder_resolution_rad
        low, high = eye_motor_range(model, mapping)
        #: The eye motor's range, whole encoder steps.
        self.step_range = (
            math.ceil(low / self.resolution_rad),
            math.floor(high / self.resolution_rad),
        )
        self._stages = tuple(
            imperfections.prepare(c, canvas)
            for c, canvas in zip(settings.cameras, self.built.canvases, strict=True)
        )
        self._taken = np.zeros((n, 2), np.int64)
        self._renderer: ViewRenderer | None = None
        #: Eye images drawn, and the heads' kinematic updates.
        self.images = 0
        self.settles = 0

    # -- the scene ---------------------------------------------------------------
    def place(self, head: int, body: str, position_world_m: np.ndarray) -> None:
        """Put mocap body ``body`` of head ``head``'s scene at ``position_world_m``."""
        body_id = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, body)
        mocap = int(self.model.body_mocapid[body_id]) if body_id >= 0 else -1
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
        """Command ``heads``' eye motors to ``steps`` and settle them (one batch call)."""
        ids = np.asarray(heads, np.int64)
        if ids.size == 0:
            return
        angles = np.empty((len(ids), 2))
        for row, (head, step) in enumerate(zip(ids, steps, strict=True)):
            commands = self._commands[head]
            angle = int(step) * self.resolution_rad
            if angle != commands.eye:
                commands.approach["eye"] = 1.0 if angle > commands.eye else -1.0
            commands.eye = angle
            true = true_targets(self.settings, commands, ("eye",))["eye"]
            angles[row] = true  # coupled: Ca2's eye follows the one motor
        self._qpos[ids[:, None], self._eyes] = angles
        self.batch.forward(ids)
        self.settles += len(ids)

    def eye_steps(self, heads: Sequence[int] | np.ndarray) -> np.ndarray:
        """``heads``' eye encoders, whole steps: the command with joint errors (they lie
        beyond the motor's shaft), else the joint, as the classic simulator reads them."""
        ids = np.asarray(heads, np.int64)
        if self.settings.joint_errors:
            read = np.array([self._commands[h].eye for h in ids])
        else:
            read = self._qpos[ids, self._eyes[0]]
        return np.round(read / self.resolution_rad).astype(np.int64)

    # -- images ------------------------------------------------------------------
    def render(self, heads: Sequence[int] | np.ndarray, camera: int) -> np.ndarray:
        """Camera ``camera`` (1 or 2) of each of ``heads``: (m, H, W, 3) uint8, full frames
        drawn through one context, each finished with its head's own noise."""
        ids = np.asarray(heads, np.int64)
        index = camera - 1
        canvas = self.built.canvases[index]
        cam_name = self.names.cameras[index]
        k = self.settings.render.supersample
        views = [
            EyeView(
                self.model, self.batch.get_data(int(h), self._data[h]), cam_name, canvas.size, k
            )
            for h in ids
        ]
        if self._renderer is None:
            largest = (
                max(c.size[0] for c in self.built.canvases),
                max(c.size[1] for c in self.built.canvases),
            )
            self._renderer = ViewRenderer(self.model, (k * largest[0], k * largest[1]))
        canvases = self._renderer.draw(views) if views else []
        size = (self.settings.cameras[index].width, self.settings.cameras[index].height)
        images = []
        for head, drawn in zip(ids, canvases, strict=True):
            shot = imperfections.Shot(
                (self.settings.seed, int(head)), int(self._taken[head, index]), size
            )
            self._taken[head, index] += 1
            images.append(imperfections.finish(_given(drawn), self._stages[index], shot))
        self.images += len(images)
        if not images:
            return np.empty((0, size[1], size[0], 3), np.uint8)
        return np.stack(images)

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


__all__ = ["SettledHeads"]
