"""The events a run's procedures and servos report, as they happen, to an event sink.

The vocabulary of a run, in the order a fixation sees them:

- :class:`PhaseStarted`: a phase ("calibration", "measurement") begins in a simulator;
- :class:`FixationStarted`: a new fixation (a target, a calibration position, a
  corner, a tracking time, a pursuit frame) begins, with its label;
- :class:`headsim.sim.events.ImageTaken`: the simulator took an image (full,
  retake, window or preview), reported by the simulator itself;
- :class:`Detected`: a servo looked for its target in the image just taken;
- :class:`Matched`: a markerless detector correlated its template there (before
  its :class:`Detected`);
- :class:`ServoStep`: a servo moved its motors and looked again;
- :class:`MeasurementDone`: a procedure finished measuring one target;
- :class:`CalibrationPosition`: the calibration finished one of its positions;
- :class:`headsim.live.gaze.PursuitFrame`: the live pursuit measured a frame.

Sinks (:class:`headsim.sim.events.EventSink`) only read them: reporting never
changes a measurement.  Images and fixations are numbered by the subscriber.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.sim.simulator import HeadSim
from headsim.vision.correspondence import Match, Template
from headsim.vision.detection import DetectionStatus


@dataclass(frozen=True)
class PhaseStarted:
    """Phase ``name`` ("calibration", "measurement") begins in ``sim``, with what the head
    knows; ``truth_world_m``: each fixation label's true target position, W, m (scoring)."""

    name: str
    sim: HeadSim
    knowledge: HeadKnowledge
    truth_world_m: Mapping[str, np.ndarray]


@dataclass(frozen=True)
class FixationStarted:
    """A new fixation begins: ``label`` names its target (a truth label of the phase)."""

    label: str


@dataclass(frozen=True)
class Detected:
    """A servo looked for its target in the image camera 1 or 2 just took.

    ``status``: what the detector said; ``uv_px``: where it found it, in the full
    frame's pixels (a window's offset added), None unless FOUND.  A detection
    in a window counts only well inside it: a miss is followed by a RETAKE image.
    """

    camera: int
    status: DetectionStatus
    uv_px: tuple[float, float] | None


@dataclass(frozen=True)
class Matched:
    """A markerless detector (:mod:`headsim.active.markerless`) correlated ``template``
    in the image camera 1 or 2 just took: the ``match`` (full-frame pixels, score,
    ambiguity, status), whatever its status.  Camera 1's template is the fovea cut at
    the click; camera 2's, camera 1's latest (what it looks for)."""

    camera: int
    match: Match
    template: Template


class ServoKind(enum.Enum):
    EYE = "eye"  # the eye motor, one camera's column (Model 2)
    NECK = "neck"  # neck yaw, neck pitch and the eye motor together (Model 1)


@dataclass(frozen=True)
class ServoStep:
    """A servo moved to ``steps`` (encoder steps: the eye's, or neck yaw, pitch and eye)
    at ``iteration`` (1, 2, ...) and looked; ``residual_px``: the image error there
    (eye: u - goal; neck: u1 - u10, u2 - u20, mean v - v0), None where the target was lost."""

    servo: ServoKind
    iteration: int
    steps: tuple[int, ...]
    residual_px: tuple[float, ...] | None


@dataclass(frozen=True)
class MeasurementDone:
    """A procedure finished measuring one target; ``time_s``: its time on a path (tracking)."""

    measurement: Measurement
    time_s: float | None = None


@dataclass(frozen=True)
class CalibrationPosition:
    """Calibration position ``index`` (from 0), at ``position_world_m`` (W, m), is done:
    its measurement (``measurement.failure`` None: fixated and used)."""

    index: int
    position_world_m: np.ndarray
    measurement: Measurement


__all__ = [
    "CalibrationPosition",
    "Detected",
    "FixationStarted",
    "Matched",
    "MeasurementDone",
    "PhaseStarted",
    "ServoKind",
    "ServoStep",
]
