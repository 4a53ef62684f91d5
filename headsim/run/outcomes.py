"""What a run found, as types: each measurement's record, the renders, the run.

Frozen dataclasses, read by the summary, the recording and the studies;
:mod:`headsim.run.serialise` is the one place that turns them into
results.json (docs/reference/results-json.md documents every key).  Each
procedure's own result is its module's (:mod:`headsim.procedures`); the
calibration's report is :mod:`headsim.active.calibration_report`'s.  Units are
in the names: m, rad, px; positions in W unless named otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

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


Vector3 = tuple[float, float, float]


def _vector(values: np.ndarray) -> Vector3:
    x, y, z = (float(v) for v in values)
    return (x, y, z)


@dataclass(frozen=True)
class MeasurementRow:
    """One measurement as plain values, for scripts and tables (NaN where it failed).

    ``status``: "ok", or why it failed; ``knowledge``: what the head knew
    (``"none"``, ``"calibrated"``).  Positions in m, world (W) or head (H) frame
    as named; ``error_m``: |estimate - truth|; ``error_pct_of_depth``: that
    error as a percentage of the true depth ``depth_m`` (z in H).  ``renders``:
    images this measurement took.  The same values as results.json's
    ``measurements``, without the covariance and the details.
    """

    name: str
    method: str
    knowledge: str
    status: str
    ok: bool
    step: int
    time_s: float | None
    estimate_world_m: Vector3
    truth_world_m: Vector3
    estimate_head_m: Vector3
    truth_head_m: Vector3
    error_m: float
    depth_m: float
    error_pct_of_depth: float
    renders: int
    search_renders: int
    scan_renders: int

    @classmethod
    def of(cls, record: MeasurementRecord) -> MeasurementRow:
        m = record.measurement
        return cls(
            name=m.name,
            method=m.method.value,
            knowledge=record.knowledge,
            status=m.status_text,
            ok=m.ok,
            step=record.step,
            time_s=record.time_s,
            estimate_world_m=_vector(m.estimate_world_m),
            truth_world_m=_vector(m.truth_world_m),
            estimate_head_m=_vector(m.estimate_head_m),
            truth_head_m=_vector(m.truth_head_m),
            error_m=float(np.linalg.norm(m.error_head_m)),
            depth_m=m.depth_m,
            error_pct_of_depth=m.error_pct_of_depth,
            renders=m.renders,
            search_renders=m.search_renders,
            scan_renders=m.scan_renders,
        )


#: The fields of :class:`MeasurementRow` that hold a 3-vector.
_VECTOR_FIELDS = ("estimate_world_m", "truth_world_m", "estimate_head_m", "truth_head_m")


def measurement_table(rows: tuple[MeasurementRow, ...]) -> dict[str, list[Any]]:
    """Columns of equal length, one entry per row: a position ``p_m`` becomes
    ``p_x_m``, ``p_y_m``, ``p_z_m``.  ``pandas.DataFrame`` takes it as it is."""
    table: dict[str, list[Any]] = {}
    for f in fields(MeasurementRow):
        if f.name in _VECTOR_FIELDS:
            stem = f.name[: -len("_m")]
            for axis, letter in enumerate("xyz"):
                table[f"{stem}_{letter}_m"] = [getattr(r, f.name)[axis] for r in rows]
        else:
            table[f.name] = [getattr(r, f.name) for r in rows]
    return table


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
class RunOutcome:
    """Everything a run found (:class:`headsim.run.result.RunResult` shows it).  ``failures``: why the run failed, one line each (empty: ok).

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

    @property
    def measurements(self) -> tuple[MeasurementRow, ...]:
        """Every measurement, in the order taken, as a :class:`MeasurementRow`."""
        return tuple(MeasurementRow.of(r) for r in self.records)

    def table(self) -> dict[str, list[Any]]:
        """The measurements as columns (:func:`measurement_table`): ``pandas.DataFrame(result.table())``."""
        return measurement_table(self.measurements)


__all__ = [
    "MeasurementRecord",
    "MeasurementRow",
    "RunOutcome",
    "RunRenders",
    "measurement_table",
]
