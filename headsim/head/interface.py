"""The smallest head the measurement path needs, and the truth channel kept apart from it.

A :class:`Head` has joints it reads and commands, two cameras it grabs from at once,
a clock, and a belief about its own geometry.  The simulator is one
(:class:`~headsim.head.sim_head.SimHead` over a :class:`~headsim.sim.simulator.HeadSim`);
:class:`~headsim.head.replay.ReplayHead` (a recording) is another; a robot's driver is a
third.  What is truly where (for placing targets and scoring) is a
:class:`Truth`, which only a simulator has: nothing measuring may ask a head for it.

Joints are the head's motors ("neck_yaw", "neck_pitch", "eye", and "eye2" with
independent eyes), angles in rad, positive as in :mod:`headsim.sim.joints`; times in s
on the head's own clock.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from headsim.head.camera_info import CameraInfo
from headsim.sim.settings import HeadBelief


@dataclass(frozen=True)
class JointReading:
    """The encoders at ``time_s``: positions, rad, and velocities, rad/s, by joint name."""

    time_s: float
    positions_rad: Mapping[str, float]
    velocities_rad_s: Mapping[str, float]


@dataclass(frozen=True)
class StampedImage:
    """One camera's image, (H, W, 3) uint8 RGB, taken at ``time_s``, with its camera
    as the head believes it."""

    time_s: float
    image: np.ndarray
    camera_info: CameraInfo


@dataclass(frozen=True)
class StereoFrame:
    """Both eyes' images (Ca1's, Ca2's) and the skew between their stamps, s."""

    left: StampedImage
    right: StampedImage

    @property
    def skew_s(self) -> float:
        """How much later Ca2's image was taken than Ca1's, s (negative: earlier)."""
        return self.right.time_s - self.left.time_s

    @property
    def time_s(self) -> float:
        """The pair's time: the mean of its stamps, s."""
        return 0.5 * (self.left.time_s + self.right.time_s)


@runtime_checkable
class Head(Protocol):
    """A stereo head with verging eyes, real or simulated (see the module docstring)."""

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Its motors, in the order :meth:`read_joints` reports them."""
        ...

    def joint_limits(self, joint: str) -> tuple[float, float]:
        """A joint's (low, high) limits, rad."""
        ...

    def read_joints(self) -> JointReading:
        """What the encoders read now."""
        ...

    def command_position(self, positions_rad: Mapping[str, float]) -> None:
        """Move the named joints to these angles, rad, and return once they are there."""
        ...

    def command_velocity(self, velocities_rad_s: Mapping[str, float], duration_s: float) -> None:
        """Turn the named joints at these rates, rad/s, for ``duration_s``, then stop."""
        ...

    def grab_stereo(self) -> StereoFrame:
        """The next image of each eye, stamped."""
        ...

    def now(self) -> float:
        """The head's clock, s."""
        ...

    @property
    def belief(self) -> HeadBelief:
        """What the head believes of its own geometry (its design or its calibration)."""
        ...

    def camera_infos(self) -> tuple[CameraInfo, CameraInfo]:
        """Each eye's camera (Ca1's, Ca2's) as the head believes it."""
        ...


class Truth(Protocol):
    """What is truly where: for placing targets and scoring, never for measuring.  Only a
    simulator has one (``HeadSim.truth``)."""

    def world_from_head(self) -> np.ndarray:
        """Pose of H in W, 4 x 4."""
        ...

    def world_from_camera(self, camera: int) -> np.ndarray:
        """Pose of camera 1 or 2's OpenCV frame in W, 4 x 4."""
        ...

    def position(self, name: str, frame: str = "world") -> np.ndarray:
        """Position of a body or site in ``frame`` ("world", "head", "cam1", "cam2"), m."""
        ...

    def transform_points(self, points: np.ndarray, src: str, dst: str) -> np.ndarray:
        """Points (N, 3) from frame ``src`` to frame ``dst``, m."""
        ...


def joint_vector(reading: JointReading, names: Sequence[str]) -> np.ndarray:
    """The reading's positions in the order ``names``, rad."""
    return np.array([reading.positions_rad[name] for name in names], dtype=float)


__all__ = ["Head", "JointReading", "StampedImage", "StereoFrame", "Truth", "joint_vector"]
