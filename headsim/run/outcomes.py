"""What a run found, as types: the calibration report, each measurement's record, the run.

Frozen dataclasses, read by the summary, the recording and the studies;
:mod:`headsim.run.serialise` is the one place that turns them into
results.json (README "Scenarios and results" documents every key).  Each
procedure's own result is its module's (:mod:`headsim.procedures`).  Units are
in the names: m, rad, px; positions in W unless named otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from headsim.active.failure import Failure
from headsim.active.measurement import Measurement
from headsim.estimators.result import Status
from headsim.scenario.spec import Scenario
from headsim.sim.events import RenderCounts

# -- the calibration (Sec. V) -------------------------------------------------------


@dataclass(frozen=True)
class CalibrationLayout:
    """Where the calibration ball was placed: the layout's kind and settings, and each position."""

    kind: str
    near_fraction: float | None
    depth_m: list[float]
    lateral: float
    vertical: float
    #: (N, 3) as drawn, or as read back from JSON
    positions_world_m: np.ndarray | list[list[float]]


@dataclass(frozen=True)
class VerticalReference:
    """The extended calibration's v0, px, and kx/ky of each camera, beside the truth."""

    v0_px: list[float]
    v0_std_px: list[float]
    v0_truth_px: list[float]
    kx_over_ky: list[float]
    kx_over_ky_std: list[float]
    kx_over_ky_truth: list[float]


@dataclass(frozen=True)
class LinesOfSightFit:
    """The extended line-of-sight fit beside the truth.

    ``std_errors_*``: 1-sigma of alpha_e, rad, and of the offsets s1, s2, m;
    ``covariance``: of (alpha_e1, alpha_e2, s1, s2).
    """

    alpha_e_rad: list[float]
    offset_m: list[float]
    std_errors_alpha_e_rad: list[float]
    std_errors_offset_m: list[float]
    offset_truth_m: list[float]
    covariance: list[list[float]]
    effective_baseline_m: float
    effective_baseline_std_m: float
    effective_baseline_truth_m: float
    separable: bool
    message: str


@dataclass(frozen=True)
class KnowledgeReport:
    """What the calibration taught the head (its :class:`HeadKnowledge`, as numbers)."""

    alpha_e_rad: list[float]
    v0_px: list[float | None]
    kx_over_ky: list[float]
    u0_px: list[float | None]
    los_offset_m: list[float] | None


@dataclass(frozen=True)
class PositionOutcome:
    """One calibration position: fixated (``failure`` None) or why not."""

    failure: Failure | None

    @property
    def status_text(self) -> str:
        """ "ok", or the failure's message (results.json's "status")."""
        return "ok" if self.failure is None else self.failure.message


@dataclass(frozen=True)
class CalibrationSource:
    """Where a calibration read from a file came from (``[experiment.calibration] from``)."""

    path: str
    scenario: str
    seed: int
    head_hash: str
    #: the renders the calibration took when it ran, by kind (None if the file does not
    #: say: one written before calibration blocks had ``render_counts``, whose
    #: ``renders`` left the previews out)
    render_counts: RenderCounts | None


@dataclass(frozen=True)
class CalibrationReport:
    """The Sec. V calibration: results.json's ``calibration`` block.

    ``status``: OK, or FAILED with ``detail`` "failed: why".  ``layout`` is None
    when the ball positions could not be laid out (nothing below it was tried);
    the fit's fields are None when the fit did not run.  ``renders``: every image the
    calibration drew, by kind (previews included; none for one read from a file).  ``rendered_frames``
    (pixels rendered, in full frames) is set by ``headsim calibrate`` only;
    ``source`` only for a calibration read from a file.
    """

    status: Status
    detail: str
    targets: int
    fixated: int
    renders: RenderCounts
    positions: tuple[PositionOutcome, ...]
    layout: CalibrationLayout | None = None
    depth_noise_m: float = 0.0
    position_noise_m: float = 0.0
    lines_of_sight_fit: bool = False
    extended: bool = False
    alpha_e_rad: list[float] | None = None
    alpha_e_std_rad: list[float] | None = None
    alpha_e_covariance_rad2: list[list[float]] | None = None
    alpha_e_truth_rad: list[float] | None = None
    alpha_e_error_rad: list[float] | None = None
    alpha_e_paper_rad: list[float] | None = None
    converged: bool = False
    depth_residual_rms_m: float | None = None
    vertical_reference: VerticalReference | None = None
    lines_of_sight: LinesOfSightFit | None = None
    knowledge: KnowledgeReport | None = None
    rendered_frames: float | None = None
    source: CalibrationSource | None = None

    @property
    def ok(self) -> bool:
        return self.status is Status.OK

    @property
    def status_text(self) -> str:
        """ "ok", or "failed: why" (results.json's "status")."""
        return "ok" if self.ok else self.detail


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
    "CalibrationLayout",
    "CalibrationReport",
    "CalibrationSource",
    "KnowledgeReport",
    "LinesOfSightFit",
    "MeasurementRecord",
    "PositionOutcome",
    "RunRenders",
    "RunResult",
    "VerticalReference",
]
