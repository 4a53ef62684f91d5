"""What a run found, as types: each measurement's record, the renders, the run.

Frozen dataclasses, read by the summary, the recording and the studies;
:mod:`headsim.runs.serialise` is the one place that turns them into
results.json (docs/reference/results-json.md documents every key).  Each
procedure's own result is its module's (:mod:`headsim.procedures`); the
calibration's report is :mod:`headsim.active.calibration_report`'s.  Units are
in the names: m, rad, px; positions in W unless named otherwise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from typing import Any, Self

import numpy as np

from headsim.active.calibration_report import CalibrationReport
from headsim.active.measurement import Measurement
from headsim.codec import declared, doc
from headsim.scenario.spec import Scenario
from headsim.scenario.surface_targets import SurfaceTarget
from headsim.sim.events import RenderCounts

# -- the run ----------------------------------------------------------------------------


@declared
class FixationScore:
    """Where a markerless target's fixation truly landed, scored (truth: never told the head).

    Each eye's goal ray (its goal column, on the row its image showed the target) at its
    true pose where its servo left it fixated (Model 2: camera 1 at step 1, camera 2 at
    step 2; Model 1: both at the neck's fixation), cast into the scene.  NaN (no
    landing) where the measurement failed.  Each field's meaning is declared with it.
    """

    vergence_error_deg: float = doc(
        "angle between eye 2's goal ray and the direction from eye 2 to the point eye 1 landed on, degrees (`null`: the measurement failed)"
    )
    error_deg: tuple[float, float] = doc(
        "each eye's goal ray against the direction to the intended target, degrees"
    )
    error_m: tuple[float, float] = doc(
        "each eye's landed point's distance from the intended target, m"
    )
    landed: tuple[str, str] = doc('the object each eye\'s ray hit (`""`: none or not converged)')
    landed_world_m: tuple[tuple[float, ...] | None, tuple[float, ...] | None] = doc(
        "each eye's landed point in W, m (`null`: none)"
    )
    click_error_px: float = doc(
        "|clicked - true| of the click in camera 1's image the head was told, px"
    )
    image_error_px: tuple[float, float] = doc(
        "each eye's look at its fixation: |where its image said the clicked surface point is - its true projection|, px (eye 1: the tracker's drift; eye 2: the correspondence error; the click's error apart)"
    )
    match_sigma_px: float | None = doc(
        "the location spread the matched template's texture allows at the image noise (Cramer-Rao, one axis), px: the theory's correspondence noise"
    )
    match_score: float | None = doc(
        "camera 2's last confident correspondence (else its last): peak NCC"
    )
    match_ambiguity: float | None = doc("its second-best peak over the best")
    match_status: str | None = doc(
        "its status (`ok`, `low texture`, `ambiguous`, `occluded`, `lost`)"
    )
    false_fixation: bool = doc(
        "the measurement is ok but an eye landed farther than `false_fixation_limit_m` from the target (or on nothing)"
    )
    false_fixation_limit_m: float = doc("that distance: 1 % of the target's depth, at least 5 mm")
    match_error_px: float = doc(
        "camera 2's last confident look: |where its match put the clicked point - its true projection|, px, whatever the measurement's outcome (`null`: no confident match)",
        default=math.nan,
    )
    wrong_match: bool = doc(
        "that error exceeds the false-fixation limit seen from camera 2 (`false_fixation_limit_m` / depth x camera 2's focal length): a confident match on the wrong point, counted also where the measurement then failed",
        default=False,
    )


#: A fixation is false beyond this fraction of the target's depth ...
FALSE_FIXATION_FRACTION = 0.01
#: ... or this distance, m, whichever is larger.
FALSE_FIXATION_MIN_M = 0.005


@dataclass(frozen=True)
class MeasurementRecord:
    """A measurement with what the head knew (``"none"``, ``"calibrated"``), its step and
    time; ``fixation``: a markerless target's landing truth (None: a marker's)."""

    measurement: Measurement
    knowledge: str
    step: int
    time_s: float | None = None
    fixation: FixationScore | None = None


@dataclass(frozen=True)
class FixationStats:
    """The fixations of markerless targets in short: vergence error median and RMS over
    those where both eyes converged (degrees; NaN: none), false fixations, confident
    wrong matches (all, and those in measurements that then failed), and the
    measurements that failed, by cause."""

    count: int
    vergence_error_deg_median: float
    vergence_error_deg_rms: float
    false_fixations: int
    failure_causes: dict[str, int]
    wrong_matches: int = 0
    wrong_matches_failed: int = 0


def fixation_stats(records: Sequence[MeasurementRecord]) -> FixationStats:
    """:class:`FixationStats` of the records with a fixation score."""
    scored = [r for r in records if r.fixation is not None]
    vergence = np.array(
        [r.fixation.vergence_error_deg for r in scored if r.fixation is not None], dtype=float
    )
    vergence = vergence[np.isfinite(vergence)]
    causes: dict[str, int] = {}
    for r in scored:
        failure = r.measurement.failure
        if failure is not None:
            causes[failure.cause.value] = causes.get(failure.cause.value, 0) + 1
    return FixationStats(
        count=len(scored),
        vergence_error_deg_median=float(np.median(vergence)) if vergence.size else math.nan,
        vergence_error_deg_rms=float(np.sqrt(np.mean(vergence**2))) if vergence.size else math.nan,
        false_fixations=sum(
            1 for r in scored if r.fixation is not None and r.fixation.false_fixation
        ),
        failure_causes=dict(sorted(causes.items(), key=lambda kv: (-kv[1], kv[0]))),
        wrong_matches=sum(1 for r in scored if r.fixation is not None and r.fixation.wrong_match),
        wrong_matches_failed=sum(
            1
            for r in scored
            if r.fixation is not None and r.fixation.wrong_match and not r.measurement.ok
        ),
    )


@declared
class TextureClassStats:
    """The markerless targets of one texture class (``rich``, ``low``, ``repetitive``,
    ``occluded``), as results.json's ``by_texture[]`` holds them (NaN: none measured,
    or none asked)."""

    texture_class: str = doc("the class")
    asked: int = doc("targets placed in it, the failed ones included")
    measured: int = doc("those measured (ok)")
    error_pct_of_depth_rms: float = doc("their 3-D error RMS, % of depth")
    vergence_error_deg_median: float = doc("median vergence error, degrees")
    vergence_error_deg_rms: float = doc("its RMS, degrees")
    false_fixations: int = doc("measurements ok with an eye landed off")
    wrong_matches: int = doc("confident matches on the wrong point")
    failure_causes: dict[str, int] = doc("failures by cause")
    renders_per_point: float = doc("renders per target asked")


def by_texture(
    records: Sequence[MeasurementRecord], classes: dict[str, str], order: Sequence[str]
) -> tuple[TextureClassStats, ...]:
    """:class:`TextureClassStats` of each class in ``order``, the records split by the class
    ``classes`` gives each target's name (a record of a name it lacks is left out)."""
    out = []
    for name in order:
        group = [r for r in records if classes.get(r.measurement.name) == name]
        pct = np.array([r.measurement.error_pct_of_depth for r in group if r.measurement.ok])
        fixation = fixation_stats(group)
        out.append(
            TextureClassStats(
                texture_class=name,
                asked=len(group),
                measured=int(pct.size),
                error_pct_of_depth_rms=float(np.sqrt(np.mean(pct**2))) if pct.size else math.nan,
                vergence_error_deg_median=fixation.vergence_error_deg_median,
                vergence_error_deg_rms=fixation.vergence_error_deg_rms,
                false_fixations=fixation.false_fixations,
                wrong_matches=fixation.wrong_matches,
                failure_causes=dict(fixation.failure_causes),
                renders_per_point=float(np.mean([r.measurement.renders for r in group]))
                if group
                else math.nan,
            )
        )
    return tuple(out)


@dataclass(frozen=True)
class SurfaceDraw:
    """How the markerless targets were drawn: ``asked`` targets, ``drawn`` draws in all,
    the ``refused`` ones by cause (each drawn again), and the ``targets`` placed;
    ``stats``: how they were fixated (None until measured); ``failure``: why none could
    be drawn ("" when they were)."""

    asked: int
    drawn: int
    refused: dict[str, int]
    targets: tuple[SurfaceTarget, ...]
    stats: FixationStats | None = None
    failure: str = ""
    by_texture: tuple[TextureClassStats, ...] = ()
    #: of ``asked``, those listed (``[[scene.room.targets]]``, first in ``targets``)
    listed: int = 0
    #: how each was measured: ``surface`` (by correlation) or ``markers`` (the twin)
    measured_as: str = "surface"


@dataclass(frozen=True)
class DrawnTarget:
    """A markerless target as results.json lists it (its point in W only)."""

    name: str
    body: str
    point_world_m: tuple[float, float, float]
    texture_class: str


@declared
class SurfaceBlock:
    """How the markerless targets were drawn and how they landed: results.json's
    ``experiment.surface_targets`` (the fixations' figures None until measured)."""

    asked: int = doc("targets asked for (`[scene.room] targets`)")
    listed: int = doc("of them, those listed (`[[scene.room.targets]]`), measured first")
    measured_as: str = doc(
        "`surface` (by correlation) or `markers` (a marker put at each point: the marker twin, `[scene.room] targets_as`)"
    )
    drawn: int = doc("draws made, refused ones included")
    refused: dict[str, int] = doc(
        "draws refused and drawn again, by cause (`no_surface`, `depth`, `occluded`, `start_view`, `reach`)"
    )
    false_fixation_limit: str = doc("the rule of a false fixation")
    targets: tuple[DrawnTarget, ...] = doc(
        "each target: `name`, the `body` it lies on, `point_world_m`, its `texture_class` (`rich`, `low`, `repetitive`, `occluded`: from truth at placement)",
        whole=True,
    )
    false_fixations: int | None = doc("measurements ok with an eye landed off the target")
    wrong_matches: int | None = doc(
        "targets whose camera 2 made a confident match on the wrong point (`wrong_match`)"
    )
    wrong_matches_failed: int | None = doc(
        "of those, the ones whose measurement then failed (not false fixations: counted here, not hidden)"
    )
    vergence_error_deg_median: float | None = doc("median vergence error of the fixations, degrees")
    vergence_error_deg_rms: float | None = doc("their RMS, degrees")
    by_texture: tuple[TextureClassStats, ...] = doc(
        "per texture class (`rich`: pink noise, `low`, `repetitive`: gratings, stripes, checks; `occluded`: part of either camera's template window hidden from the other at the start pose), always all four"
    )

    @classmethod
    def of(cls, draw: SurfaceDraw) -> SurfaceBlock:
        """The block of ``draw``."""
        stats = draw.stats
        return cls(
            asked=draw.asked,
            listed=draw.listed,
            measured_as=draw.measured_as,
            drawn=draw.drawn,
            refused=draw.refused,
            false_fixation_limit=f"max({FALSE_FIXATION_FRACTION:g} x depth, "
            f"{FALSE_FIXATION_MIN_M:g} m)",
            targets=tuple(
                DrawnTarget(t.name, t.body, t.point_world_m, t.texture_class) for t in draw.targets
            ),
            false_fixations=None if stats is None else stats.false_fixations,
            wrong_matches=None if stats is None else stats.wrong_matches,
            wrong_matches_failed=None if stats is None else stats.wrong_matches_failed,
            vergence_error_deg_median=None if stats is None else stats.vergence_error_deg_median,
            vergence_error_deg_rms=None if stats is None else stats.vergence_error_deg_rms,
            by_texture=draw.by_texture,
        )


@declared
class SurfaceResult:
    """A procedure's result on each target (Model 2, Model 1, the one-step fixation): with
    markerless targets (``[scene.room] targets``), how they were drawn; ``failure``: why
    some could not be (empty: none)."""

    surface_targets: SurfaceBlock | None = doc(
        "how the markerless targets were drawn and how they landed",
        default=None,
        omit_if_none=True,
    )
    failure: str = doc("", default="", skip=True)

    @classmethod
    def of(cls, draw: SurfaceDraw) -> Self:
        """The result of measuring the targets of ``draw``."""
        return cls(SurfaceBlock.of(draw), draw.failure)

    def failures(self) -> tuple[str, ...]:
        """Markerless targets that could not be drawn."""
        return (self.failure,) if self.failure else ()


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


@declared
class RunRenders:
    """Every image a run's simulators drew (whole frames, windows, retakes and previews:
    each one a render), by phase: results.json's ``render_counts``.

    ``in_measurements``: the experiment's renders that its measurements count (their
    ``renders`` summed); ``outside_measurements`` the rest: renders of the procedure
    that belong to no measurement (relative positioning's four images of the objects
    at the two fixations; every frame of a live pursuit, which records none).
    ``overall``: the calibration's and the experiment's together.
    """

    calibration: RenderCounts = doc("during the calibration")
    experiment: RenderCounts = doc("during the experiment")
    in_measurements: int = doc(
        "`experiment` only: the sum of its measurements' `renders`",
        key="experiment.in_measurements",
    )
    outside_measurements: int = doc(
        "`experiment` only: renders of the procedure that belong to no measurement",
        key="experiment.outside_measurements",
        init=False,
        compare=False,
    )
    overall: RenderCounts = doc("both", init=False, compare=False)

    def __post_init__(self) -> None:
        outside = self.experiment.total - self.in_measurements
        object.__setattr__(self, "outside_measurements", outside)
        object.__setattr__(self, "overall", self.calibration + self.experiment)


@dataclass(frozen=True)
class RunOutcome:
    """Everything a run found (:class:`headsim.runs.result.RunResult` shows it).  ``failures``: why the run failed, one line each (empty: ok).

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
    "FALSE_FIXATION_FRACTION",
    "FALSE_FIXATION_MIN_M",
    "DrawnTarget",
    "FixationScore",
    "FixationStats",
    "MeasurementRecord",
    "MeasurementRow",
    "RunOutcome",
    "RunRenders",
    "SurfaceBlock",
    "SurfaceDraw",
    "SurfaceResult",
    "TextureClassStats",
    "by_texture",
    "fixation_stats",
    "measurement_table",
]
