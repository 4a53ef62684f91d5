"""A servo-level head that replays a recording's looks
(:func:`~headsim.head.mcap_log.read_grabs`): :class:`ReplayServoHead`.

It serves a procedure the images it took when recording, in order: each grab (a whole
frame, a retake, a window, a preview) is the recording's next one, which must be of the
same camera, region of interest and binning.  Its motors are position controlled: the
encoders read what was last commanded, in whole steps, once settled (a head in kinematic
settling, or whose encoders sit on the motor shafts: the quick start's); each grab's
recorded joint state must agree with them.  A procedure that drives it as it drove the
recorded head sees the same images and encoders, and gives the same estimates bit for
bit; one that strays raises :class:`~headsim.head.replay.ReplayDiverged`, naming where.
It has no truth: its measurements are unscored.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NoReturn

import numpy as np

from headsim.head.camera_info import CameraInfo, camera_info_of
from headsim.head.interface import JointReading, StampedImage, StereoFrame
from headsim.head.mcap_log import Grab
from headsim.head.replay import ReplayDiverged
from headsim.head.servo_head import NoTruth
from headsim.sim.events import NO_EVENTS, EventSink
from headsim.sim.render import Window
from headsim.sim.settings import CameraSettings, HeadBelief, HeadSettings, SettingsError


class ReplayServoHead:
    """A :class:`~headsim.head.servo_head.ServoHead` serving recorded ``grabs`` in order.

    ``settings``: the head's specification (encoder resolution, image sizes and centres,
    its belief); ``limits``: each motor's (low, high) range, rad (a recording holds none).
    """

    def __init__(
        self,
        grabs: Sequence[Grab],
        settings: HeadSettings,
        limits: Mapping[str, tuple[float, float]],
        sink: EventSink = NO_EVENTS,
    ) -> None:
        if not grabs:
            raise ReplayDiverged("the recording holds no images to replay")
        self._grabs = tuple(grabs)
        self._settings = settings
        self._limits = dict(limits)
        self._sink = sink
        self._next = 0
        self._motors = tuple(self._grabs[0].positions_rad)
        self._commands = dict(self._grabs[0].positions_rad)

    # -- the head's specification ------------------------------------------------------
    @property
    def settings(self) -> HeadSettings:
        return self._settings

    @property
    def sink(self) -> EventSink:
        return self._sink

    @property
    def motors(self) -> tuple[str, ...]:
        return self._motors

    @property
    def joint_names(self) -> tuple[str, ...]:
        return self._motors

    @property
    def belief(self) -> HeadBelief:
        return self._settings.believed

    @property
    def render_count(self) -> int:
        """Grabs served so far."""
        return self._next

    @property
    def remaining(self) -> int:
        """Recorded grabs not yet served."""
        return len(self._grabs) - self._next

    @property
    def truth(self) -> NoReturn:
        raise NoTruth("a replayed head has no truth channel")

    def camera_settings(self, camera: int) -> CameraSettings:
        return self._settings.cameras[camera - 1]

    def camera_infos(self) -> tuple[CameraInfo, CameraInfo]:
        """Each eye's camera as its specification gives it."""
        first, second = self._settings.cameras
        return camera_info_of(first.pinhole(), "cam1"), camera_info_of(second.pinhole(), "cam2")

    def joint_range(self, motor: str) -> tuple[float, float]:
        try:
            return self._limits[motor]
        except KeyError:
            raise SettingsError(f"no limits given for motor {motor!r}") from None

    def joint_limits(self, joint: str) -> tuple[float, float]:
        return self.joint_range(joint)

    # -- encoders: the commands, in whole steps ----------------------------------------
    def _steps(self, motor: str) -> int:
        return round(self._commands[motor] / self._settings.encoder_resolution_rad)

    def _reading(self, motor: str) -> float:
        return self._steps(motor) * self._settings.encoder_resolution_rad

    def eye_encoder_steps(self) -> int:
        return self._steps("eye")

    def encoder_steps(self, motor: str) -> int:
        return self._steps(motor)

    def neck_encoders(self) -> tuple[float, float]:
        return tuple(  # type: ignore[return-value]
            self._reading(m) if m in self._commands else 0.0 for m in ("neck_yaw", "neck_pitch")
        )

    def now(self) -> float:
        return self._grabs[min(self._next, len(self._grabs) - 1)].time_s

    def read_joints(self) -> JointReading:
        positions = {m: self._reading(m) for m in self._motors}
        return JointReading(self.now(), positions, dict.fromkeys(self._motors, 0.0))

    # -- commands ----------------------------------------------------------------------
    def command(
        self,
        *,
        neck_yaw: float | None = None,
        neck_pitch: float | None = None,
        eye: float | None = None,
        eye2: float | None = None,
    ) -> None:
        asked = {"neck_yaw": neck_yaw, "neck_pitch": neck_pitch, "eye": eye, "eye2": eye2}
        if eye is not None and eye2 is None and "eye2" in self._motors:
            asked["eye2"] = eye
        for motor, angle in asked.items():
            if angle is not None and motor in self._commands:
                self._commands[motor] = float(angle)

    def command_eye_steps(self, steps: int) -> None:
        self.command(eye=int(steps) * self._settings.encoder_resolution_rad)

    def settle(self) -> None:
        """Nothing to wait for: the recording's next image was taken settled."""

    def move(self, **targets: float) -> None:
        self.command(**targets)

    def command_position(self, positions_rad: Mapping[str, float]) -> None:
        self.command(**positions_rad)

    def command_velocity(self, velocities_rad_s: Mapping[str, float], duration_s: float) -> None:
        self.command(
            **{m: self._commands[m] + rate * duration_s for m, rate in velocities_rad_s.items()}
        )

    # -- grabs -------------------------------------------------------------------------
    def _grab(self, camera: int, window: Window | None, binning: int) -> np.ndarray:
        n = self._next
        if n >= len(self._grabs):
            raise ReplayDiverged(f"the recording holds {len(self._grabs)} images; asked for more")
        grab = self._grabs[n]
        asked = (camera, window, binning)
        if (grab.camera, grab.window, grab.binning) != asked:
            raise ReplayDiverged(
                f"image {n + 1}: asked for camera {camera}, window {window}, binning {binning}; "
                f"the recording took camera {grab.camera}, window {grab.window}, "
                f"binning {grab.binning}"
            )
        for motor, angle in grab.positions_rad.items():
            if motor in self._commands and angle != self._reading(motor):
                raise ReplayDiverged(
                    f"image {n + 1}: {motor} at {self._reading(motor)!r} rad; the recording "
                    f"was at {angle!r} rad"
                )
        self._next += 1
        return grab.image

    def render(self, camera: int) -> np.ndarray:
        return self._grab(camera, None, 1)

    def retake(self, camera: int) -> np.ndarray:
        return self._grab(camera, None, 1)

    def render_window(self, camera: int, window: Window, retake: bool = False) -> np.ndarray:
        return self._grab(camera, window, 1)

    def render_preview(self, camera: int, binning: int) -> np.ndarray:
        return self._grab(camera, None, binning)

    def grab_stereo(self) -> StereoFrame:
        time_s = self.now()
        left, right = self.camera_infos()
        return StereoFrame(
            StampedImage(time_s, self.render(1), left), StampedImage(time_s, self.render(2), right)
        )


__all__ = ["ReplayServoHead"]
