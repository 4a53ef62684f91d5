"""A run recorded as ROS 2 messages in MCAP (``headsim run ... --mcap FILE``).

A :class:`McapRun` follows the run's events: every whole image a camera takes goes
out with its CameraInfo as the head believes it, the encoders (``JointState``), the
eye frames' TF and, when it changed, the position command the image was taken at;
every measurement's estimate goes out as a point in the head frame.  A servo's windows
go out as images of their region of interest (the CameraInfo's ``roi``) and its previews
binned (``binning_x``/``binning_y``), so that a replay
(:class:`~headsim.head.replay_servo.ReplayServoHead`) serves a procedure every look it
took; each phase's start is a ``std_msgs/String`` on ``/headsim/phase``.

Times: a run in the simulator has no wall clock of its own, so the n-th image of the run
is stamped n frame periods (:data:`~headsim.head.sim_head.FRAME_PERIOD_S`) after the start.
"""

from __future__ import annotations

from pathlib import Path

from headsim.active.events import PhaseStarted
from headsim.head.interface import JointReading, StampedImage
from headsim.head.mcap_log import McapRecorder, believed_head_from_cameras
from headsim.head.sim_head import FRAME_PERIOD_S, SimHead
from headsim.runs.events import MeasurementRecorded, Stamp
from headsim.sim.events import ImageTaken


class McapRun:
    """A run's :class:`~headsim.runs.events.Subscriber` writing ``path`` (close it after)."""

    def __init__(self, path: str | Path) -> None:
        self.recorder = McapRecorder(path)
        self._head: SimHead | None = None
        self._commanded: dict[str, float] | None = None
        self._time_s = 0.0
        #: Images written (whole frames, windows and previews).
        self.images = 0

    def notify(self, event: object, at: Stamp) -> None:
        if isinstance(event, PhaseStarted):
            self._head = SimHead(event.sim)
            self._commanded = None
            self.recorder.phase(event.name, max(at.frame, 0) * FRAME_PERIOD_S)
        elif isinstance(event, ImageTaken):
            if self._head is not None:
                self._image(event, at)
        elif isinstance(event, MeasurementRecorded):
            m = event.record.measurement
            self.recorder.estimate(m.name, m.estimate_head_m, self._time_s)

    def _image(self, event: ImageTaken, at: Stamp) -> None:
        assert self._head is not None
        self._time_s = max(at.frame, 0) * FRAME_PERIOD_S
        sim = self._head.sim
        commanded = sim.commanded()
        if commanded != self._commanded:
            self.recorder.command("position", commanded, self._time_s)
            self._commanded = commanded
        reading = self._head.read_joints()
        reading = JointReading(self._time_s, reading.positions_rad, reading.velocities_rad_s)
        self.recorder.joints(reading)
        self.recorder.eye_frames(
            self._time_s, believed_head_from_cameras(sim.belief, reading.positions_rad)
        )
        info = self._head.camera_infos()[event.camera - 1]
        stamped = StampedImage(self._time_s, event.image, info)
        self.recorder.image(event.camera, stamped, event.window, event.binning)
        self.images += 1

    def close(self) -> None:
        self.recorder.close()


__all__ = ["McapRun"]
