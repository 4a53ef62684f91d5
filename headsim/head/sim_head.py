"""The simulator as a :class:`~headsim.head.interface.Head` and a
:class:`~headsim.head.servo_head.ServoHead`: :class:`SimHead` over a
:class:`~headsim.sim.simulator.HeadSim`.  The servo-level calls pass straight to the
simulator (the same calls in the same order: a run through it is the simulator's run).

Its clock is MuJoCo's time plus what commanded motions and grabs took: a position
command settles at once (kinematic settling) or by the physics' steps, a velocity
command moves each joint's command by rate x duration, and a stereo grab takes one
frame period (both eyes at the same instant: skew 0).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from headsim.head.camera_info import CameraInfo, camera_info_of
from headsim.head.interface import JointReading, StampedImage, StereoFrame
from headsim.sim.events import EventSink
from headsim.sim.render import Window
from headsim.sim.settings import CameraSettings, HeadBelief, HeadSettings, SettingsError
from headsim.sim.simulator import HeadSim, SettleResult

#: The frame period of :meth:`SimHead.grab_stereo`, s (30 frames a second).
FRAME_PERIOD_S = 1.0 / 30.0


class SimHead:
    """A :class:`HeadSim` behind the :class:`~headsim.head.interface.Head` interface.

    ``camera_infos``: each eye's camera as the head believes it (its calibration);
    default: its cameras' own intrinsics, as a Zhang calibration gives them to within
    its error, read through the truth channel when first asked for).  :attr:`truth` is
    the simulator's truth channel, for placing and scoring.
    """

    def __init__(
        self, sim: HeadSim, camera_infos: tuple[CameraInfo, CameraInfo] | None = None
    ) -> None:
        self.sim = sim
        self._camera_infos = camera_infos
        self._elapsed_s = 0.0

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Its motors: "neck_yaw" (if it has one), "neck_pitch", "eye" and, with
        independent eyes, "eye2"."""
        return self.sim.motors

    def joint_limits(self, joint: str) -> tuple[float, float]:
        return self.sim.joint_range(joint)

    @property
    def belief(self) -> HeadBelief:
        return self.sim.belief

    def camera_infos(self) -> tuple[CameraInfo, CameraInfo]:
        if self._camera_infos is None:
            cameras, names = self.sim.truth.settings.cameras, self.sim.names.cameras
            self._camera_infos = (
                camera_info_of(cameras[0].pinhole(), names[0]),
                camera_info_of(cameras[1].pinhole(), names[1]),
            )
        return self._camera_infos

    def now(self) -> float:
        return float(self.sim.data.time) + self._elapsed_s

    def read_joints(self) -> JointReading:
        """The encoders (quantised), rad, and the joints' speeds, rad/s (0 at rest)."""
        sim = self.sim
        yaw, pitch = sim.neck_encoders()
        eye1, eye2 = sim.eye_encoders()
        positions = {"neck_yaw": yaw, "neck_pitch": pitch, "eye": eye1, "eye2": eye2}
        speeds = sim.joint_speeds()
        return JointReading(
            self.now(),
            {motor: positions[motor] for motor in sim.motors},
            {motor: speeds[motor] for motor in sim.motors},
        )

    def command_position(self, positions_rad: Mapping[str, float]) -> None:
        self.sim.move(**positions_rad)

    def command_velocity(self, velocities_rad_s: Mapping[str, float], duration_s: float) -> None:
        """Each named motor's command moved by rate x ``duration_s``, then settled."""
        if not (math.isfinite(duration_s) and duration_s >= 0):
            raise SettingsError(f"duration_s must be finite and >= 0, got {duration_s}")
        commanded = self.sim.commanded()
        unknown = sorted(set(velocities_rad_s) - set(commanded))
        if unknown:
            raise SettingsError(
                f"this head has no motor {unknown[0]!r}; allowed: {', '.join(self.sim.motors)}"
            )
        self.sim.move(
            **{m: commanded[m] + rate * duration_s for m, rate in velocities_rad_s.items()}
        )
        if self.sim.settle_mode == "kinematic":
            self._elapsed_s += duration_s

    def grab_stereo(self) -> StereoFrame:
        """Both eyes' next full images, taken at one instant; then one frame period passes."""
        time_s = self.now()
        left, right = self.camera_infos()
        frame = StereoFrame(
            StampedImage(time_s, self.sim.render(1), left),
            StampedImage(time_s, self.sim.render(2), right),
        )
        self._elapsed_s += FRAME_PERIOD_S
        return frame

    # -- the servo level (ServoHead): the simulator's own calls ------------------------
    @property
    def settings(self) -> HeadSettings:
        return self.sim.settings

    @property
    def sink(self) -> EventSink:
        return self.sim.sink

    @property
    def motors(self) -> tuple[str, ...]:
        return self.sim.motors

    @property
    def render_count(self) -> int:
        return self.sim.render_count

    @property
    def truth(self) -> HeadSim:
        return self.sim.truth

    def camera_settings(self, camera: int) -> CameraSettings:
        return self.sim.camera_settings(camera)

    def joint_range(self, motor: str) -> tuple[float, float]:
        return self.sim.joint_range(motor)

    def eye_encoder_steps(self) -> int:
        return self.sim.eye_encoder_steps()

    def encoder_steps(self, motor: str) -> int:
        return self.sim.encoder_steps(motor)

    def neck_encoders(self) -> tuple[float, float]:
        return self.sim.neck_encoders()

    def command(
        self,
        *,
        neck_yaw: float | None = None,
        neck_pitch: float | None = None,
        eye: float | None = None,
        eye2: float | None = None,
    ) -> None:
        self.sim.command(neck_yaw=neck_yaw, neck_pitch=neck_pitch, eye=eye, eye2=eye2)

    def command_eye_steps(self, steps: int) -> None:
        self.sim.command_eye_steps(steps)

    def settle(self) -> SettleResult:
        return self.sim.settle()

    def move(self, **targets: float) -> SettleResult:
        return self.sim.move(**targets)

    def render(self, camera: int) -> np.ndarray:
        return self.sim.render(camera)

    def retake(self, camera: int) -> np.ndarray:
        return self.sim.retake(camera)

    def render_window(self, camera: int, window: Window, retake: bool = False) -> np.ndarray:
        return self.sim.render_window(camera, window, retake=retake)

    def render_preview(self, camera: int, binning: int) -> np.ndarray:
        return self.sim.render_preview(camera, binning)


__all__ = ["FRAME_PERIOD_S", "SimHead"]
