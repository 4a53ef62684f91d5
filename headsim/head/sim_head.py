"""The simulator as a :class:`~headsim.head.interface.Head`: :class:`SimHead` over a
:class:`~headsim.sim.simulator.HeadSim`.

Its clock is MuJoCo's time plus what commanded motions and grabs took: a position
command settles at once (kinematic settling) or by the physics' steps, a velocity
command moves each joint's command by rate x duration, and a stereo grab takes one
frame period (both eyes at the same instant: skew 0).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from headsim.head.camera_info import CameraInfo, camera_info_of
from headsim.head.interface import JointReading, StampedImage, StereoFrame
from headsim.sim.settings import HeadBelief, SettingsError
from headsim.sim.simulator import HeadSim

#: The frame period of :meth:`SimHead.grab_stereo`, s (30 frames a second).
FRAME_PERIOD_S = 1.0 / 30.0


class SimHead:
    """A :class:`HeadSim` behind the :class:`~headsim.head.interface.Head` interface.

    ``camera_infos``: each eye's camera as the head believes it (its calibration);
    default: its cameras' own intrinsics, as a Zhang calibration gives them to within
    its error.  ``sim.truth`` stays on the simulator, out of this interface.
    """

    def __init__(
        self, sim: HeadSim, camera_infos: tuple[CameraInfo, CameraInfo] | None = None
    ) -> None:
        self.sim = sim
        cameras = sim.names.cameras
        self._camera_infos = camera_infos or (
            camera_info_of(sim.settings.cameras[0].pinhole(), cameras[0]),
            camera_info_of(sim.settings.cameras[1].pinhole(), cameras[1]),
        )
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
        left, right = self._camera_infos
        frame = StereoFrame(
            StampedImage(time_s, self.sim.render(1), left),
            StampedImage(time_s, self.sim.render(2), right),
        )
        self._elapsed_s += FRAME_PERIOD_S
        return frame


__all__ = ["FRAME_PERIOD_S", "SimHead"]
