"""What a run found, as types: each measurement's record, the renders, the run.

Frozen dataclasses, read by the summary, the recording and the studies;
:mod:`headsim.run.serialise` is the one place that turns them into
results.json (docs/reference/results-json.md documents every key).  Each
procedure's own result is its module's (:mod:`headsim.procedures`); the
calibration's report is :mod:`headsim.active.calibration_report`'s.  Units are
in the names: m, rad, px; positions in W unless named otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from headsim.active.calibration_report import CalibrationReport
from headsim.active.measurement import Measurement
from headsim.scenario.spec import Scenario
from headsim.sim.events import RenderCounts

# -- the run ----------------------------------------------------------------------------


@dataclass(frozen=True)
class MeasurementRecord:
    """A measurement with what the head knew (``"none"``, ``"calibrated"``), its step and time."""

    measurement: Measurement
    knowledge: str
    step: int
    time_s: float | None = None


@dataclass(frozen=True)
class RunRenders:
    """Every image a run's simulators drew (whole frames, windows, retakes and previews:
    each one a render), by phase.

    ``in_measurements``: the experiment's renders that its measurements count (their
    ``renders`` summed); ``outside_measurements`` the rest: renders of the procedure
    that belong to no measurement (relative positioning's four images of the objects
    at the two fixations; every frame of a live pursuit, which records none).
    """

    calibration: RenderCounts
    experiment: RenderCounts
    in_measurements: int

    @property
    def overall(self) -> RenderCounts:
        """The calibration's and the experiment's together."""
        return self.calibration + self.experiment

    @property
    def outside_measurements(self) -> int:
        """The experiment's renders that no measurement counts."""
        return self.experiment.total - self.in_measurements

    def as_dict(self) -> dict[str, Any]:
        """results.json's ``render_counts``: each phase's and the run's renders by kind; the
        experiment's split into those its measurements count and the rest."""
        return {
            "calibration": self.calibration.as_dict(),
            "experiment": {
                **self.experiment.as_dict(),
                "in_measurements": self.in_measurements,
                "outside_measurements": self.outside_measurements,
            },
            "overall": self.overall.as_dict(),
        }


@dataclass(frozen=True)
class RunResult:
    """Everything a run found.  ``failures``: why the run failed, one line each (empty: ok).

    ``experiment``: the procedure's own result (None: the procedure did not run,
    the calibration failed).  ``renders``: every image drawn, by phase and kind.
    ``timing_s``: wall time by phase (not in results.json).
    """

    scenario: Scenario
    calibration: CalibrationReport | None
    records: tuple[MeasurementRecord, ...]
    experiment: Any
    renders: RunRenders
    failures: tuple[str, ...]
    timing_s: dict[str, float] = field(default_factory=dict, compare=False)
    #: Pixels rendered by phase, in full frames (a window counts its share, a preview
    #: its binned pixels).
    rendered_frames: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not self.failures


__all__ = [
    "MeasurementRecord",
    "RunRenders",
    "RunResult",
]
