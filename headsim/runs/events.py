"""A run's events fanned out to its subscribers (progress, recording), and the runner's own events.

The simulator, the servos and the procedures report what happens to an event
sink (:mod:`headsim.sim.events`, :mod:`headsim.active.events`); the runner
gives them a :class:`Hub`.  The hub numbers the images (``frame``) and the
fixations (``step``) over the whole run, counts what was rendered, and passes
every event with its :class:`Stamp` to each :class:`Subscriber`.  Nothing is
rendered for the subscribers: they see the experiment's own images.

The runner adds three events of its own: :class:`MeasurementRecorded` (a
measurement with what the head knew and its step), :class:`CalibrationDone`
(the calibration's report) and :class:`RunFinished`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from headsim.active.events import FixationStarted, PhaseStarted
from headsim.errors import raise_if_interrupted
from headsim.sim.events import ImageKind, ImageTaken, RenderCounts

if TYPE_CHECKING:
    from headsim.active.calibration_report import CalibrationReport
    from headsim.runs.outcomes import MeasurementRecord, RunOutcome


@dataclass(frozen=True)
class Stamp:
    """Where in the run an event happened: ``frame``, the number of the image taken last
    (this one, for an image; previews are not numbered; -1 before the first), and
    ``step``, the fixation under way (-1 before the first)."""

    frame: int
    step: int


@dataclass(frozen=True)
class MeasurementRecorded:
    """The runner recorded a measurement (with what the head knew, its step and time)."""

    record: MeasurementRecord


@dataclass(frozen=True)
class CalibrationDone:
    """The calibration is finished, or failed: its report."""

    report: CalibrationReport


@dataclass(frozen=True)
class RunFinished:
    """The run is over."""

    result: RunOutcome


class Subscriber(Protocol):
    """Anything that follows a run: each event in order, with where in the run it happened."""

    def notify(self, event: object, at: Stamp) -> None: ...


class Hub:
    """The runner's event sink: numbers frames and steps, counts renders, tells the subscribers.

    ``renders``: every image the simulators drew, by kind (whole frames, windows,
    retakes, previews: each one a render, as ``HeadSim.render_count`` counts them);
    ``rendered_frames``: their pixels, in full frames (a window counts its share).
    ``steps``: the steps begun in the current phase, in order.
    """

    def __init__(self, subscribers: Sequence[Subscriber] = ()) -> None:
        self.subscribers = list(subscribers)
        self.frame = -1
        self.step = -1
        self.steps: list[int] = []
        self.rendered_frames = 0.0
        self.renders = RenderCounts()

    def emit(self, event: object) -> None:
        """Count and number ``event``, then pass it to every subscriber (first, stop
        if an interrupt arrived that Python swallowed: see ``raise_if_interrupted``)."""
        raise_if_interrupted()
        if isinstance(event, PhaseStarted):
            self.steps = []
        elif isinstance(event, FixationStarted):
            self.step += 1
            self.steps.append(self.step)
        elif isinstance(event, ImageTaken):
            self.rendered_frames += event.rendered_frames
            self.renders = self.renders.counted(event.kind)
            if event.kind is not ImageKind.PREVIEW:  # previews are not shown: not numbered
                self.frame += 1
        stamp = Stamp(self.frame, self.step)
        for subscriber in self.subscribers:
            subscriber.notify(event, stamp)

    def begin(self, label: str) -> int:
        """A new fixation (``label``) begins; returns its step."""
        self.emit(FixationStarted(label))
        return self.step


__all__ = [
    "CalibrationDone",
    "Hub",
    "MeasurementRecorded",
    "RunFinished",
    "Stamp",
    "Subscriber",
]
