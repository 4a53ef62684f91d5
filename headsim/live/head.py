"""The live head: time, a camera frame rate, exposure with motion blur, latency, motors.

Time advances in MuJoCo physics steps (``model.opt.timestep``, 2 ms).  Frame
``k`` is exposed over ``[k T, k T + E]`` (T = 1 / frame rate, E = exposure);
with motion blur on, its image is the mean of ``blur_subframes`` renders at
the centres of equal slices of the exposure (each render is one full render:
blur costs ``blur_subframes`` times the render time), else a single render at
mid-exposure.  Encoders are latched at mid-exposure, as a camera's strobe
output would latch them.  A command sent after frame ``k`` takes effect
``latency_frames`` frame periods after that frame's exposure ended.

Joints move only through the motors (:mod:`headsim.live.motors`), so an image
taken while the eyes move sees them where the physics put them, and each
encoder reads its joint to the count (no backlash on the live head).  The target
is a mocap body (a marker, or a room's textured object) moved along its path at every
physics step.

The live head is the simulator run in time over a :class:`~headsim.head.sim_head.SimHead`:
it grabs its images from the head and reads the encoders' specification there; the
physics it steps, the motors it drives and the target it moves are the simulator's
world, reached through the head's truth channel (placing is the simulator's job).  What
measures on it (:mod:`headsim.live.gaze`) takes its frames, sends it commands and drives
:attr:`LiveHead.head`; only a frame's ``truth_*`` fields carry the truth, for scoring.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import mujoco
import numpy as np

from headsim.head.sim_head import SimHead
from headsim.live.motors import MotorDriver, MotorLimits, motor_joints
from headsim.live.paths import Path, Visibility
from headsim.sim.settings import SettingsError

#: Where a target that is not present is parked (world, m): under the table, out of view.
PARKED_WORLD_M = np.array([0.0, 0.5, -5.0])
#: Default motor limits: eye motor (rad/s, rad/s^2), neck motors.
EYE_LIMITS = MotorLimits(max_speed=8.0, max_accel=300.0)
NECK_LIMITS = MotorLimits(max_speed=3.0, max_accel=60.0)


@dataclass(frozen=True)
class LiveConfig:
    """Timing of the live head: frame rate (Hz), exposure (s), blur sub-frames, latency (frames)."""

    frame_rate_hz: float = 30.0
    exposure_s: float = 0.0
    blur_subframes: int = 1
    latency_frames: int = 1
    eye_limits: MotorLimits = EYE_LIMITS
    neck_limits: MotorLimits = NECK_LIMITS
    servo_bandwidth_hz: float = 20.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.frame_rate_hz) and 1.0 <= self.frame_rate_hz <= 1000.0):
            raise SettingsError(
                f"frame_rate_hz must be within [1, 1000] Hz, got {self.frame_rate_hz}"
            )
        if not (
            math.isfinite(self.exposure_s) and 0.0 <= self.exposure_s <= 1.0 / self.frame_rate_hz
        ):
            raise SettingsError(
                f"exposure_s must be within [0, 1 / frame_rate_hz = {1.0 / self.frame_rate_hz:.4f}] s, got {self.exposure_s}"
            )
        if not (isinstance(self.blur_subframes, int) and 1 <= self.blur_subframes <= 64):
            raise SettingsError(
                f"blur_subframes must be an integer within [1, 64], got {self.blur_subframes!r}"
            )
        if not (isinstance(self.latency_frames, int) and 0 <= self.latency_frames <= 30):
            raise SettingsError(
                f"latency_frames must be an integer within [0, 30], got {self.latency_frames!r}"
            )
        if not (math.isfinite(self.servo_bandwidth_hz) and 1.0 <= self.servo_bandwidth_hz <= 60.0):
            raise SettingsError(
                f"servo_bandwidth_hz must be within [1, 60] Hz, got {self.servo_bandwidth_hz}"
            )

    @property
    def period_s(self) -> float:
        return 1.0 / self.frame_rate_hz

    @property
    def latency_s(self) -> float:
        return self.latency_frames * self.period_s

    @property
    def motion_blur(self) -> bool:
        return self.blur_subframes > 1 and self.exposure_s > 0


@dataclass(frozen=True)
class Frame:
    """One stereo frame: images, the encoders latched at mid-exposure, and truth for scoring.

    ``encoders_rad``: (neck yaw, neck pitch, eye motor), quantised like the
    head's encoders.  ``truth_*`` fields are for scoring and recording only.
    """

    index: int
    time_s: float  # mid-exposure
    end_s: float  # end of exposure: when the image is available
    images: tuple[np.ndarray, np.ndarray]
    encoders_rad: np.ndarray
    truth_target_world_m: np.ndarray | None
    truth_joints_rad: np.ndarray


Command = Callable[[MotorDriver, float], None]


@dataclass
class _Queued:
    due_s: float
    order: int
    command: Command = field(compare=False)


class LiveHead:
    """A :class:`SimHead`'s simulator run in time: motors, a moving target, frames at a rate."""

    def __init__(
        self,
        head: SimHead,
        config: LiveConfig | None = None,
        target_body: str | None = None,
        path: Path | None = None,
        visibility: Visibility | None = None,
        point_offset_m: np.ndarray | None = None,
    ) -> None:
        """``point_offset_m``: the scored point's offset from the moved body's centre, W, m
        (a textured object's clicked surface point; the path moves the centre)."""
        #: The head it grabs from (and the at-rest servo drives, :func:`headsim.live.gaze.acquire`).
        self.head = head
        world = head.truth  # the physics, the motors' actuators and the target's body
        self._model, self._data = world.model, world.data
        self.point_offset_m = None if point_offset_m is None else np.asarray(point_offset_m)
        self.config = config or LiveConfig()
        self.dt = float(self._model.opt.timestep)
        limits = (self.config.neck_limits, self.config.neck_limits, self.config.eye_limits)
        self.motors = MotorDriver(
            self._model, self._data, limits, self.config.servo_bandwidth_hz, world.names
        )
        self._qadr = [int(self._model.joint(j).qposadr[0]) for j in motor_joints(world.names)]
        self._mocap = -1
        if target_body is not None:
            body_id = mujoco.mj_name2id(self._model, mujoco.mjtObj.mjOBJ_BODY, target_body)
            self._mocap = int(self._model.body_mocapid[body_id]) if body_id >= 0 else -1
            if self._mocap < 0:
                raise SettingsError(f"{target_body!r} is not a movable (mocap) body in this scene")
        self.path = path
        self.visibility = visibility or Visibility()
        self.step_count = 0
        self.frame_index = 0
        self._queue: list[_Queued] = []
        self._order = 0
        self._place_target()
        mujoco.mj_forward(self._model, self._data)
        self.motors.sync()

    # -- time ----------------------------------------------------------------
    @property
    def time_s(self) -> float:
        return self.step_count * self.dt

    def _steps_at(self, time_s: float) -> int:
        return round(time_s / self.dt)

    def target_truth(self, time_s: float) -> np.ndarray | None:
        """Where the target (its point ``point_offset_m`` from the body's centre) is at
        ``time_s`` (world, m), None when it is not present."""
        if self.path is None or not self.visibility.visible(time_s):
            return None
        centre = self.path.position(time_s)
        return centre if self.point_offset_m is None else centre + self.point_offset_m

    def _place_target(self) -> None:
        if self._mocap < 0 or self.path is None:
            return
        present = self.visibility.visible(self.time_s)
        centre = self.path.position(self.time_s) if present else PARKED_WORLD_M
        self._data.mocap_pos[self._mocap] = centre

    def advance_to(self, time_s: float) -> None:
        """Step the physics, motors and target until ``time_s`` (rounded to a physics step)."""
        goal = self._steps_at(time_s)
        while self.step_count < goal:
            now = self.time_s
            while self._queue and self._queue[0].due_s <= now + 1e-12:
                self._queue.pop(0).command(self.motors, now)
            self.motors.advance(now, self.dt)
            mujoco.mj_step(self._model, self._data)
            self.step_count += 1
            self._place_target()
        mujoco.mj_forward(self._model, self._data)

    def send(self, command: Command, frame: Frame) -> None:
        """Queue ``command(motors, time_s)`` to act ``latency_frames`` periods after ``frame`` ended."""
        self._order += 1
        self._queue.append(_Queued(frame.end_s + self.config.latency_s, self._order, command))
        self._queue.sort(key=lambda q: (q.due_s, q.order))

    def now(self, command: Command) -> None:
        """Apply ``command`` at once (e.g. a Gymnasium action)."""
        command(self.motors, self.time_s)

    # -- sensing -------------------------------------------------------------
    def encoders(self) -> np.ndarray:
        """(neck yaw, neck pitch, eye) encoder readings now, rad: each joint to its count.

        The live joints move through the motors, so an encoder reads its joint, quantised:
        the true angle lies anywhere within the count read (``count_error``'s model,
        always).  The at-rest readings (``sim.neck_encoders``) would give the last at-rest
        command on a head with joint errors.  Backlash is not modelled here.
        """
        resolution = self.head.settings.encoder_resolution_rad
        return np.round(self.true_joints() / resolution) * resolution

    def true_joints(self) -> np.ndarray:
        """(neck yaw, neck pitch, eye) as the physics has them now, rad (truth: for the
        encoders' model and for scoring)."""
        return np.array([float(self._data.qpos[a]) for a in self._qadr])

    def capture(self) -> Frame:
        """Advance to the next frame's exposure and take it (both cameras)."""
        cfg = self.config
        start = self.frame_index * cfg.period_s
        if start < self.time_s - 1e-9:  # time ran past a frame: take the next one due
            self.frame_index = math.ceil(self.time_s / cfg.period_s - 1e-9)
            start = self.frame_index * cfg.period_s
        middle, end = start + cfg.exposure_s / 2, start + cfg.exposure_s
        if cfg.motion_blur:
            n = cfg.blur_subframes
            sums: list[np.ndarray | None] = [None, None]
            encoders = joints = truth = None
            for i in range(n):
                self.advance_to(start + (i + 0.5) * cfg.exposure_s / n)
                for cam in range(2):
                    image = self.head.render(cam + 1).astype(np.float32)
                    total = sums[cam]
                    sums[cam] = image if total is None else total + image
                if self._steps_at(middle) <= self.step_count and encoders is None:
                    encoders, joints = self.encoders(), self.true_joints()
            first, second = sums
            assert first is not None and second is not None and encoders is not None
            assert joints is not None
            images = tuple(
                np.clip(np.rint(s / n), 0, 255).astype(np.uint8) for s in (first, second)
            )
            truth = self.target_truth(middle)
            self.advance_to(end)
        else:
            self.advance_to(middle)
            images = (self.head.render(1), self.head.render(2))
            encoders, joints, truth = self.encoders(), self.true_joints(), self.target_truth(middle)
        frame = Frame(
            self.frame_index,
            self._steps_at(middle) * self.dt,
            max(end, self.time_s),
            (images[0], images[1]),
            encoders,
            truth,
            joints,
        )
        self.frame_index += 1
        return frame
