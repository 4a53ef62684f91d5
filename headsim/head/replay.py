"""A head that replays a recording (:func:`~headsim.head.mcap_log.read_log`).

It serves the recording's stereo pairs in order: each of Ca1's images with Ca2's image
nearest in time (the pairing ROS's ``ApproximateTimeSynchronizer`` makes), and the
joints linearly interpolated to the next pair's time.  Its clock is that time.
Commands move nothing: each is checked against the recording's, in order, so a
procedure that drives the head as it did when recording sees the same images and
encoders, and gives the same estimates bit for bit.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from headsim.errors import JobFailed
from headsim.head.camera_info import CameraInfo
from headsim.head.interface import JointReading, StampedImage, StereoFrame
from headsim.head.mcap_log import Command, HeadLog
from headsim.sim.settings import HeadBelief


class ReplayDiverged(JobFailed):
    """A replayed procedure asked for something the recording does not hold."""


def pair_by_stamp(
    left: tuple[StampedImage, ...], right: tuple[StampedImage, ...]
) -> list[StereoFrame]:
    """Each left image with the right image nearest in time (the earlier on a tie)."""
    stamps = np.array([image.time_s for image in right])
    pairs = []
    for image in left:
        nearest = int(np.argmin(np.abs(stamps - image.time_s)))
        pairs.append(StereoFrame(image, right[nearest]))
    return pairs


class ReplayHead:
    """A :class:`~headsim.head.interface.Head` serving a :class:`HeadLog` by time."""

    def __init__(
        self,
        log: HeadLog,
        belief: HeadBelief | None = None,
        limits: Mapping[str, tuple[float, float]] | None = None,
        check_commands: bool = True,
    ) -> None:
        self.log = log
        self._belief = belief or HeadBelief()
        self._limits = dict(limits or {})
        self._pairs = pair_by_stamp(*log.images)
        self._next = 0
        self._commands = 0
        self.check_commands = check_commands

    @property
    def joint_names(self) -> tuple[str, ...]:
        return self.log.joints.names

    def joint_limits(self, joint: str) -> tuple[float, float]:
        """As given (a recording holds none), else unbounded."""
        return self._limits.get(joint, (-np.inf, np.inf))

    @property
    def belief(self) -> HeadBelief:
        return self._belief

    def camera_infos(self) -> tuple[CameraInfo, CameraInfo]:
        pair = self._pairs[min(self._next, len(self._pairs) - 1)]
        return pair.left.camera_info, pair.right.camera_info

    @property
    def remaining(self) -> int:
        """Stereo pairs not yet grabbed."""
        return len(self._pairs) - self._next

    def now(self) -> float:
        """The next pair's time (after the last: the last pair's), s."""
        return self._pairs[min(self._next, len(self._pairs) - 1)].time_s

    def read_joints(self) -> JointReading:
        """The joints interpolated to :meth:`now`; velocities from the neighbouring samples."""
        time_s = self.now()
        track = self.log.joints
        positions = track.at(time_s)
        velocities = {}
        for j, name in enumerate(track.names):
            gradient = (
                np.gradient(track.positions_rad[:, j], track.times_s)
                if len(track.times_s) > 1 and np.all(np.diff(track.times_s) > 0)
                else np.zeros(len(track.times_s))
            )
            velocities[name] = float(np.interp(time_s, track.times_s, gradient))
        return JointReading(time_s, positions, velocities)

    def grab_stereo(self) -> StereoFrame:
        if self._next >= len(self._pairs):
            raise ReplayDiverged(
                f"the recording holds {len(self._pairs)} stereo pairs; a replay asked for more"
            )
        pair = self._pairs[self._next]
        self._next += 1
        return pair

    def _command(self, kind: str, values: Mapping[str, float]) -> None:
        if not self.check_commands:
            return
        recorded: tuple[Command, ...] = self.log.commands
        if self._commands >= len(recorded):
            raise ReplayDiverged(
                f"command {self._commands + 1} ({kind}) is beyond the recording's {len(recorded)}"
            )
        expected = recorded[self._commands]
        if expected.kind != kind or dict(expected.values) != {
            k: float(v) for k, v in values.items()
        }:
            raise ReplayDiverged(
                f"command {self._commands + 1} differs from the recording's: "
                f"{kind} {dict(values)} against {expected.kind} {dict(expected.values)}"
            )
        self._commands += 1

    def command_position(self, positions_rad: Mapping[str, float]) -> None:
        self._command("position", positions_rad)

    def command_velocity(self, velocities_rad_s: Mapping[str, float], duration_s: float) -> None:
        self._command("velocity", velocities_rad_s)


__all__ = ["ReplayDiverged", "ReplayHead", "pair_by_stamp"]
