"""What makes :class:`~headsim.head.ros_head.RosHead` a
:class:`~headsim.head.servo_head.ServoHead`: its specification, whole-step commands and
settling, the encoders in steps, and one eye's grabs (:class:`RosServo`, which RosHead
takes its servo-level calls from).

A robot tells its specification through what it publishes and what its owner gives:
each camera's size and K from its ``CameraInfo``
(:func:`~headsim.head.camera_info.camera_settings_from`), the encoder resolution,
joint limits, the head's model (its neck, for eq. (3)) and its belief.  A command
publishes position targets without waiting; :meth:`RosServo.settle` waits for a joint
state stamped after the last command with every commanded joint within the head's
tolerance of it.  The encoders are the joint states rounded to whole steps.  One eye's
grab takes that eye's next image taken since the motors settled and crops its region of
interest or bins it on the host (a camera driver without hardware ROI or binning), so
every grab but a retake costs a whole frame.  A robot has no truth channel.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, NoReturn

import numpy as np

from headsim.errors import JobFailed
from headsim.head.camera_info import CameraInfo, camera_settings_from
from headsim.head.interface import JointReading
from headsim.head.servo_head import NoTruth
from headsim.sim.events import EventSink, ImageKind, ImageTaken, RenderCounts
from headsim.sim.heads import HeadModel
from headsim.sim.joints import JointLimitError
from headsim.sim.render import Window
from headsim.sim.settings import CameraSettings, HeadBelief, HeadSettings, SettingsError


def binned(image: np.ndarray, binning: int) -> np.ndarray:
    """``image`` (H, W, 3) uint8 binned ``binning`` x ``binning``: each pixel the rounded
    mean of its block, (H/b, W/b, 3) uint8."""
    height, width = image.shape[:2]
    if binning < 1 or height % binning or width % binning:
        raise ValueError(f"binning {binning} must divide the {width}x{height} image")
    blocks = image.reshape(height // binning, binning, width // binning, binning, -1)
    return np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8)


def head_settings(
    infos: tuple[CameraInfo, CameraInfo],
    encoder_resolution_rad: float,
    belief: HeadBelief,
    model: HeadModel,
) -> HeadSettings:
    """A robot's specification: its cameras' sizes and K, its encoder resolution, its
    model and its belief (the lengths are the believed ones: a robot knows no others)."""
    return HeadSettings(
        baseline_m=belief.baseline_m,
        neck_d1_m=belief.neck_d1_m,
        neck_a2_m=belief.neck_a2_m,
        encoder_resolution_rad=encoder_resolution_rad,
        cameras=(camera_settings_from(infos[0]), camera_settings_from(infos[1])),
        belief=belief,
        head=model,
    )


class RosServo:
    """The :class:`~headsim.head.servo_head.ServoHead` calls of a
    :class:`~headsim.head.ros_head.RosHead` (see the module docstring)."""

    if TYPE_CHECKING:  # what RosHead provides

        @property
        def joint_names(self) -> tuple[str, ...]: ...

        @property
        def belief(self) -> HeadBelief: ...

        def camera_infos(self) -> tuple[CameraInfo, CameraInfo]: ...

        def read_joints(self) -> JointReading: ...

        def _publish_position(self, positions_rad: Mapping[str, float]) -> None: ...

        def _await_position(self, positions_rad: Mapping[str, float]) -> JointReading: ...

        def _next_image(self, camera: int) -> np.ndarray: ...

    def _init_servo(
        self,
        encoder_resolution_rad: float | None,
        limits: Mapping[str, tuple[float, float]],
        model: HeadModel,
        sink: EventSink,
    ) -> None:
        self._resolution_rad = encoder_resolution_rad
        self._limits = dict(limits)
        self._model = model
        self._sink = sink
        self._settings: HeadSettings | None = None
        #: Commands published since the motors last settled, rad, by motor.
        self._pending: dict[str, float] = {}
        #: Each eye's image last grabbed (a retake's), and the images grabbed so far.
        self._taken: list[np.ndarray | None] = [None, None]
        self._counts = RenderCounts()

    # -- the head's specification ------------------------------------------------------
    @property
    def settings(self) -> HeadSettings:
        """Its specification (the module docstring); waits for the cameras' CameraInfo."""
        if self._settings is None:
            if self._resolution_rad is None:
                raise SettingsError(
                    "the ROS 2 head needs its encoder_resolution_rad (one encoder step of "
                    "its joints, rad) to be driven by a servo"
                )
            self._settings = head_settings(
                self.camera_infos(), self._resolution_rad, self.belief, self._model
            )
        return self._settings

    @property
    def sink(self) -> EventSink:
        return self._sink

    @property
    def motors(self) -> tuple[str, ...]:
        return self.joint_names

    def camera_settings(self, camera: int) -> CameraSettings:
        return self.settings.cameras[camera - 1]

    def joint_range(self, motor: str) -> tuple[float, float]:
        """A motor's (low, high) limits, rad, as given to the head."""
        try:
            return self._limits[motor]
        except KeyError:
            raise SettingsError(
                f"the ROS 2 head was given no limits for motor {motor!r} (limits=...)"
            ) from None

    @property
    def truth(self) -> NoReturn:
        raise NoTruth("a ROS 2 head has no truth channel")

    # -- encoders: the joint states in whole steps --------------------------------------
    def encoder_steps(self, motor: str) -> int:
        reading = self.read_joints().positions_rad
        if motor not in reading:
            raise SettingsError(f"the joint states carry no {motor!r}")
        return round(reading[motor] / self.settings.encoder_resolution_rad)

    def eye_encoder_steps(self) -> int:
        return self.encoder_steps("eye")

    def neck_encoders(self) -> tuple[float, float]:
        """The neck's (yaw, pitch) encoders, rad, in whole steps (a head without a neck
        yaw reads 0)."""
        resolution = self.settings.encoder_resolution_rad
        yaw = self.encoder_steps("neck_yaw") * resolution if "neck_yaw" in self.motors else 0.0
        return yaw, self.encoder_steps("neck_pitch") * resolution

    # -- commands ------------------------------------------------------------------------
    def command(
        self,
        *,
        neck_yaw: float | None = None,
        neck_pitch: float | None = None,
        eye: float | None = None,
        eye2: float | None = None,
    ) -> None:
        """Publish the named motors' position targets, rad, without waiting (``eye``
        alone moves both eyes of independent eyes, as on the simulator)."""
        asked = {"neck_yaw": neck_yaw, "neck_pitch": neck_pitch, "eye": eye, "eye2": eye2}
        if eye is not None and eye2 is None and "eye2" in self.motors:
            asked["eye2"] = eye
        targets = {motor: float(a) for motor, a in asked.items() if a is not None}
        for motor, angle in targets.items():
            if motor not in self.motors:
                raise SettingsError(
                    f"this head has no motor {motor!r}; allowed: {', '.join(self.motors)}"
                )
            low, high = self._limits.get(motor, (-math.inf, math.inf))
            if not (math.isfinite(angle) and low <= angle <= high):
                raise JointLimitError(
                    f"command {angle!r} rad for {motor} is outside its range [{low}, {high}] rad"
                )
        if targets:
            self._pending.update(targets)
            self._publish_position(targets)

    def command_eye_steps(self, steps: int) -> None:
        self.command(eye=int(steps) * self.settings.encoder_resolution_rad)

    def settle(self) -> JointReading:
        """Wait until every motor commanded since the last settle is within tolerance of
        its command (a joint state stamped after the command); the joint state that
        ended it (the current one when nothing was commanded)."""
        if not self._pending:
            return self.read_joints()
        reading = self._await_position(self._pending)
        self._pending = {}
        return reading

    def move(self, **targets: float) -> JointReading:
        """:meth:`command` then :meth:`settle`."""
        self.command(**targets)
        return self.settle()

    # -- one eye's grabs ---------------------------------------------------------------
    @property
    def render_count(self) -> int:
        """Images grabbed so far: each eye's of a stereo grab, frames, windows, retakes and
        previews, each one."""
        return self._counts.total

    @property
    def render_counts(self) -> RenderCounts:
        """Images grabbed so far, by kind (a stereo grab's two are frames)."""
        return self._counts

    def _taken_image(
        self,
        camera: int,
        image: np.ndarray,
        kind: ImageKind,
        window: Window | None = None,
        binning: int = 1,
    ) -> np.ndarray:
        """Count and report ``image``: a fresh one cost a whole frame, a retake nothing."""
        self._counts = self._counts.counted(kind)
        frames = 0.0 if kind is ImageKind.RETAKE else 1.0
        self._sink.emit(ImageTaken(camera, image, kind, frames, window, binning))
        return image

    def _grab(self, camera: int) -> np.ndarray:
        """Camera 1 or 2's next image taken since the motors settled (waiting for one)."""
        image = self._next_image(camera)
        self._taken[camera - 1] = image
        return image

    def _retaken(self, camera: int) -> np.ndarray:
        image = self._taken[camera - 1]
        if image is None:
            raise JobFailed(f"the ROS 2 head: nothing grabbed from camera {camera} to retake")
        return image

    def render(self, camera: int) -> np.ndarray:
        """Camera 1 or 2's next whole image, (H, W, 3) uint8 RGB."""
        return self._taken_image(camera, self._grab(camera), ImageKind.FULL)

    def retake(self, camera: int) -> np.ndarray:
        """The whole image camera 1 or 2 last gave (the same exposure)."""
        return self._taken_image(camera, self._retaken(camera), ImageKind.RETAKE)

    def render_window(self, camera: int, window: Window, retake: bool = False) -> np.ndarray:
        """Only ``window`` of camera 1 or 2's next image (``retake``: of its last), cropped
        here, (h, w, 3) uint8."""
        image = self._retaken(camera) if retake else self._grab(camera)
        crop = np.ascontiguousarray(image[window.y0 : window.y1, window.x0 : window.x1])
        kind = ImageKind.RETAKE if retake else ImageKind.WINDOW
        return self._taken_image(camera, crop, kind, window)

    def render_preview(self, camera: int, binning: int) -> np.ndarray:
        """Camera 1 or 2's next image binned ``binning`` x ``binning`` here (:func:`binned`)."""
        preview = binned(self._grab(camera), binning)
        return self._taken_image(camera, preview, ImageKind.PREVIEW, binning=binning)


__all__ = ["RosServo", "binned", "head_settings"]
