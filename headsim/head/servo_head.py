"""What the servos and procedures need of a head beyond :class:`~headsim.head.interface.Head`:
windowed grabs, whole-step commands and settling, the encoders in steps, and the truth
channel kept apart.

A servo looks at as few pixels as its answer needs: a region of interest of one eye's
image (``Window``, as ROS's ``CameraInfo.roi``), a binned preview of the whole view, or
the whole frame, and again of the same instant after a window missed (a retake).  It
moves the eye motor by whole encoder steps (a position command of ``steps x
encoder_resolution_rad``) and waits for the motors to stop (:meth:`ServoHead.settle`)
before it looks.  :class:`~headsim.head.sim_head.SimHead` implements it over the
simulator; a robot's driver implements it over its cameras' ROI and its position
controller.

``settings`` is the head's specification (encoder resolution, image sizes and centres,
its model and what it believes of itself); ``truth`` is the simulator's truth channel,
for placing targets and scoring only (a real head has none).  The truth-channel test
runs scenarios on a simulator that refuses every other read of either.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

from headsim.head.interface import Head
from headsim.sim.events import EventSink
from headsim.sim.render import Window
from headsim.sim.settings import CameraSettings, HeadSettings

if TYPE_CHECKING:
    from headsim.sim.simulator import HeadSim


class NoTruth(RuntimeError):
    """A head without a truth channel (a replay, a robot) was asked for the truth."""


class Specified(Protocol):
    """Anything that tells a head's specification (a :class:`ServoHead`, the simulator)."""

    @property
    def settings(self) -> HeadSettings:
        """Its specification: only what a head's data sheet and belief give may be read."""
        ...


@runtime_checkable
class ServoHead(Head, Specified, Protocol):
    """A :class:`~headsim.head.interface.Head` as the servos drive it (module docstring).

    Cameras are 1 and 2 (the paper's Ca1 and Ca2); motors as in :attr:`Head.joint_names`.
    """

    @property
    def sink(self) -> EventSink:
        """Where the head, and the servos driving it, report what they see and do."""
        ...

    @property
    def motors(self) -> tuple[str, ...]:
        """Its motors (:attr:`Head.joint_names`)."""
        ...

    @property
    def render_count(self) -> int:
        """Images grabbed so far: frames, windows, retakes and previews, each one."""
        ...

    def camera_settings(self, camera: int) -> CameraSettings:
        """Camera 1 or 2's specification (image size and centre)."""
        ...

    def joint_range(self, motor: str) -> tuple[float, float]:
        """A motor's (low, high) limits, rad (:meth:`Head.joint_limits`)."""
        ...

    # -- encoders ------------------------------------------------------------------------
    def eye_encoder_steps(self) -> int:
        """Ca1's eye motor's encoder, whole steps."""
        ...

    def encoder_steps(self, motor: str) -> int:
        """A motor's encoder, whole steps."""
        ...

    def neck_encoders(self) -> tuple[float, float]:
        """The neck's (yaw, pitch) encoders, rad."""
        ...

    # -- commands: positions, then wait until the motors stop ---------------------------
    def command(
        self,
        *,
        neck_yaw: float | None = None,
        neck_pitch: float | None = None,
        eye: float | None = None,
        eye2: float | None = None,
    ) -> None:
        """Command the named motors' positions, rad, without waiting (see :meth:`settle`)."""
        ...

    def command_eye_steps(self, steps: int) -> None:
        """Command the eye motor to ``steps`` whole encoder steps, without waiting."""
        ...

    def settle(self) -> object:
        """Wait until the motors stop at their commands."""
        ...

    def move(self, **targets: float) -> object:
        """Command the named motors' positions, rad, and wait until they stop there."""
        ...

    # -- grabs -------------------------------------------------------------------------
    def render(self, camera: int) -> np.ndarray:
        """Camera 1 or 2's next whole image, (H, W, 3) uint8 RGB."""
        ...

    def retake(self, camera: int) -> np.ndarray:
        """The whole image of the instant just grabbed as a window (the same exposure)."""
        ...

    def render_window(self, camera: int, window: Window, retake: bool = False) -> np.ndarray:
        """Only ``window`` (the region of interest) of the next image, (h, w, 3) uint8;
        ``retake``: of the instant just grabbed."""
        ...

    def render_preview(self, camera: int, binning: int) -> np.ndarray:
        """The whole view binned ``binning`` x ``binning``, (H/b, W/b, 3) uint8."""
        ...

    # -- the truth channel -------------------------------------------------------------
    @property
    def truth(self) -> HeadSim:
        """What is truly where: for placing targets and scoring, never for measuring
        (:class:`NoTruth` on a head that has none)."""
        ...


__all__ = ["NoTruth", "ServoHead", "Specified"]
