"""results.json from the typed results: its document declared once, key by key.

``results.json`` (every key's meaning is read from the declarations below and in the
types they hold, :mod:`headsim.runs.results_reference`) holds no wall time and no
timestamp: the same scenario, seed and software give the same bytes.  SI units (m,
rad, px); NaN becomes null when :func:`headsim.files.write_json_atomic` writes it.
The ``calibration`` block, which a calibration file (head.json) holds too, is a
:class:`~headsim.active.calibration_report.CalibrationReport`'s.
"""

from __future__ import annotations

import platform
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from importlib import metadata
from typing import Any

import cv2
import mujoco
import numpy as np

from headsim.active.calibration_report import CalibrationReport
from headsim.active.failure import Failure, FailureCause
from headsim.active.measurement import Measurement
from headsim.codec import declared, describe, doc, encode, keys
from headsim.estimators.result import Method, Status
from headsim.head.offline import TargetEstimate
from headsim.runs.accuracy import MeasurementSummary, summaries
from headsim.runs.outcomes import FixationScore, MeasurementRecord, RunOutcome, RunRenders
from headsim.scenario.schema import SETTLE
from headsim.scenario.spec import experiment_record
from headsim.sim.events import RenderCounts
from headsim.sim.settings import (
    HeadBelief,
    belief_meanings,
    record_meanings,
    settings_record,
)
from headsim.version import __version__

#: Version of the results.json layout; bumped when a key changes meaning or goes.
RESULTS_SCHEMA = "headsim.results/2"

_COUNTS = "full frames, windows, retakes and previews"


def software_versions() -> dict[str, str]:
    """Versions of what produced the numbers."""

    def version(package: str) -> str:
        try:
            return metadata.version(package)
        except metadata.PackageNotFoundError:
            return "not installed"

    return {
        "headsim": __version__,
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "scipy": version("scipy"),  # not imported for it (0.1 s)
        "opencv": cv2.__version__,
        "rerun-sdk": version("rerun-sdk"),
    }


@declared
class MeasurementEntry:
    """One measurement as results.json's ``measurements[]`` holds it."""

    name: str = doc(
        "the target (`corner_i_j` for chessboard corners, `blocks` for the cross point)"
    )
    method: Method = doc(
        "`model2`, `model1`, `fixation`, or `stereo_triangulation` (`headsim estimate`)"
    )
    status: str = doc(
        '`"ok"`, or why it failed (`"Ca2 at step 1: target lost (and at 12 eye angles searched)"`, ...)'
    )
    failure: Failure | None = doc(
        "`null`, or the cause: `cause` (`lost`, `cut`, `occluded`, `low texture`, `ambiguous`, `joint limit`, `iteration limit`, `estimator`), `stage` (`step 1`, `step 2`, `fixation`, `estimate`), `camera` (1, 2 or `null`), `detail`",
        whole=True,
    )
    knowledge: str = doc('what the head knew: `"none"` or `"calibrated"`')
    step: int = doc("its step in the recording")
    time_s: float | None = doc("tracking: the target's time, s; else `null`")
    estimate_head_m: np.ndarray = doc("the estimate in H, m")
    truth_head_m: np.ndarray = doc("the truth in H, m")
    estimate_world_m: np.ndarray = doc("the estimate in W through eq. (3) and the neck encoders, m")
    truth_world_m: np.ndarray = doc("the truth in W, m")
    error_head_m: np.ndarray = doc("estimate minus truth in H, m")
    error_m: float = doc("its length, m")
    depth_m: float = doc("the true depth z_h, m")
    error_pct_of_depth: float = doc("`error_m` in % of `depth_m`")
    covariance_head_m2: np.ndarray = doc("first-order covariance of the estimate in H, m^2")
    renders: int = doc(f"renders this measurement took ({_COUNTS})")
    search_renders: int = doc("renders it spent finding a lost target again (in `renders`)")
    scan_renders: int = doc(
        "renders of `search_renders` spent scanning the joints' ranges for a target the head's pose did not show"
    )
    servo_residual_px: tuple[float, ...] = doc("each servo's final image offset from its goal, px")
    details: dict[str, float] = doc("angles and pixels used (`alpha1_rad`, `u11_px`, ...)")
    fixation: FixationScore | None = doc(
        "a markerless target's landing truth (`[scene.room] targets`; `null`: a marker's): each eye's goal ray at its true pose where its servo converged (Model 2: camera 1 at step 1, camera 2 at step 2; Model 1: both at the fixation), cast into the scene; truth, never told the head"
    )

    @classmethod
    def of(cls, record: MeasurementRecord) -> MeasurementEntry:
        """The entry of ``record``."""
        m = record.measurement
        return cls(
            name=m.name,
            method=m.method,
            status=m.status_text,
            failure=m.failure,
            knowledge=record.knowledge,
            step=record.step,
            time_s=record.time_s,
            estimate_head_m=m.estimate_head_m,
            truth_head_m=m.truth_head_m,
            estimate_world_m=m.estimate_world_m,
            truth_world_m=m.truth_world_m,
            error_head_m=m.error_head_m,
            error_m=float(np.linalg.norm(m.error_head_m)),
            depth_m=m.depth_m,
            error_pct_of_depth=m.error_pct_of_depth,
            covariance_head_m2=m.covariance_head_m2,
            renders=m.renders,
            search_renders=m.search_renders,
            scan_renders=m.scan_renders,
            servo_residual_px=m.servo_residual_px,
            details=m.details,
            fixation=record.fixation,
        )


@declared
class ScenarioRecord:
    """The scenario as run: results.json's ``scenario``."""

    name: str = doc("the scenario's name")
    file: str = doc("its file's name")
    description: str = doc("its `description`")
    procedure: str = doc("its `[experiment] procedure`")
    fast: bool = doc("whether the fast variant ran")
    preset: str = doc("the head preset (`ideal`, `paper`, `realistic`)")
    scene: dict[str, Any] = doc(
        "the checked scene: every placement in W, random ones drawn",
        parts={
            "scene": "the MJCF scene",
            "targets": "the targets to measure, each a placement in W",
            "chessboard": "the chessboard's placement, or `null`",
            "corners": "the chessboard's inner corners (columns, rows), or `null`",
            "blocks": "the crossed blocks' placement, or `null`",
            "objects": "the relative-positioning objects' placements",
            "parked": "the bodies parked out of sight",
            "moving": "the moving target's path, or `null`",
            "pursuit": "the live pursuit's target and path, or `null`",
            "room": "the textured room (`[scene.room]`): its seed, surface texture, table and walls, every object (clutter drawn from the seed included) and the light; `null`: none",
            "surface_targets": "`[scene.room] targets` and its keys (`count`, `depth_m`, `lateral`, `vertical`, `click_error_px`, `band_px`, `listed`, `targets_as`); `null`: none",
            "acceptance": "how the targets came to be measured (`null`: a procedure without targets)",
            "acceptance.within": "`[scene.random_targets] within` (`box` or `reach`; `null`: no random targets)",
            "acceptance.listed": "the `[[scene.targets]]` entries",
            "acceptance.drawn": "random draws made, refused ones included",
            "acceptance.refused": "draws the reach check refused, by reason (`depth`, `eye_range`, `neck_range`, `neck_offset`, `not_in_any_view`, `occluded`, `start_view`)",
            "acceptance.accepted": "the targets measured, listed and drawn",
            "acceptance.outside_start_view": "the names of the accepted targets the start pose does not show whole to both cameras",
        },
    )
    experiment: dict[str, Any] = doc("the `[experiment]` options as read (the servo's included)")


def _phase_parts() -> dict[str, str]:
    """``render_counts``' keys, ``*`` one phase, from :class:`RunRenders`' declaration: each
    phase's counts, then the experiment's own."""
    own = {
        path.removeprefix("experiment."): meaning
        for path, meaning in describe(RunRenders).items()
        if path.startswith("experiment.")
    }
    return {
        "*": "one phase: `calibration`, `experiment` or `overall`",
        **{f"*.{key}": meaning for key, meaning in {**describe(RenderCounts), **own}.items()},
    }


_PHASE_PARTS = _phase_parts()


@declared
class ResultsDocument:
    """results.json: its keys in the order written."""

    schema: str = doc(
        '`"headsim.results/2"` (2: one render count, every image drawn, previews included, in `render_counts`)'
    )
    scenario: ScenarioRecord = doc(
        "the scenario as run: its file, its procedure and its checked scene"
    )
    seed: int = doc("the seed used")
    status: str = doc('`"ok"` or `"failed"`')
    failures: tuple[str, ...] = doc(
        "one line per failed measurement (or calibration, or object not seen)"
    )
    software: dict[str, str] = doc(
        "versions of headsim, Python, MuJoCo, NumPy, SciPy, OpenCV, rerun-sdk"
    )
    settings: dict[str, Any] = doc(
        "the true head",
        parts={**record_meanings(), "settle_mode": SETTLE.meaning.removesuffix(".")},
    )
    belief: dict[str, Any] = doc(
        "what the head believed and measured with",
        parts={
            **belief_meanings(),
            "sources": "where each believed quantity above came from: `design` (the head's design), `preset` (the realistic preset's own belief), `file` (the scenario's `[belief]`), `given` (a `HeadBelief` given in Python), or `truth` (equal to the true head's, which the scenario changed in `[head]` and the belief followed)",
        },
    )
    render_counts: RunRenders = doc(
        "every image the simulator drew, each one a render",
        whole=True,
        parts=_PHASE_PARTS,
    )
    rendered_frames: dict[str, float] = doc(
        "pixels rendered, in full frames (a window counts its share; also in `timing.json`)",
        parts={
            "calibration": "during the calibration",
            "experiment": "during the experiment",
            "total": "both",
        },
    )
    calibration: CalibrationReport | None = doc(
        "`null`, or the Sec. V calibration (a calibration file holds the same block)"
    )
    measurements: tuple[MeasurementEntry, ...] = doc("one entry per measurement, in order")
    summary: dict[str, MeasurementSummary] = doc(
        "the measurements' statistics, per knowledge",
        each='one knowledge (`"none"`, `"calibrated"`)',
    )
    experiment: dict[str, Any] = doc(
        "the procedure's own results (below)",
        parts={"procedure": "the procedure's name"},
    )


#: Keys of results.json and of each measurement in it, in the order written.
RESULTS_KEYS = keys(ResultsDocument)
MEASUREMENT_KEYS = keys(MeasurementEntry)


# -- each procedure's experiment ---------------------------------------------------------


def experiment_block(procedure: str, experiment: object | None) -> dict[str, Any]:
    """results.json's ``experiment``: the procedure, then its result's fields (none if it did not run)."""
    return {
        "procedure": procedure,
        **({} if experiment is None else encode(experiment)),
    }


def results_document(result: RunOutcome) -> ResultsDocument:
    """What results.json holds of ``result``."""
    s = result.scenario
    edge = () if s.scene.acceptance is None else s.scene.acceptance.outside_start_view
    return ResultsDocument(
        schema=RESULTS_SCHEMA,
        scenario=ScenarioRecord(
            name=s.name,
            file=s.path.name,
            description=s.description,
            procedure=s.experiment.procedure,
            fast=s.fast,
            preset=s.preset,
            scene=asdict(s.scene),
            experiment=experiment_record(s.experiment),
        ),
        seed=s.seed,
        status="ok" if result.ok else "failed",
        failures=result.failures,
        software=software_versions(),
        settings={**settings_record(s.settings), "settle_mode": s.settle_mode},
        # The truth above; what the head believes (and its estimators use) here.
        belief={**asdict(s.settings.believed), "sources": s.believed_from},
        render_counts=result.renders,
        rendered_frames=result.rendered_frames,
        calibration=result.calibration,
        measurements=tuple(MeasurementEntry.of(r) for r in result.records),
        summary=summaries(result.records, edge),
        experiment=experiment_block(s.experiment.procedure, result.experiment),
    )


# -- an offline estimate's (``headsim estimate``) ----------------------------------------


@declared
class EstimateDocument:
    """results.json of ``headsim estimate``: the run's keys that a recording has, in the
    run's order (``source`` in place of ``scenario``), its measurements the run's entries."""

    schema: str = doc("the run's schema (`results.json`'s `schema`)")
    source: str = doc("the recording estimated from")
    status: str = doc('`"ok"` or `"failed"`')
    failures: tuple[str, ...] = doc("one line per target not found in both images of any pair")
    software: dict[str, str] = doc(
        "versions of headsim, Python, MuJoCo, NumPy, SciPy, OpenCV, rerun-sdk"
    )
    belief: dict[str, Any] = doc(
        "what the mapping's `[head]` says the head is (`baseline_m`, `neck_d1_m`, `neck_a2_m`, `nodal_offset_m`, `side_offset_m`), and `alpha_e_rad`, each eye's initial direction"
    )
    stereo_pairs: int = doc("Ca1's images, each paired with Ca2's nearest in time")
    measurements: tuple[MeasurementEntry, ...] = doc(
        "one entry per target of the mapping, in order: the median of its pairs' triangulations "
        "(`details.pairs`: how many; `details.seen`: pairs it was looked for in); truth and "
        "errors only with `--truth` (in H; nothing in W: a recording has no world)"
    )
    summary: dict[str, MeasurementSummary] = doc(
        "the measurements' statistics, per knowledge",
        each='one knowledge (`"none"`; `"calibrated"`: the mapping gives initial directions)',
    )


def estimate_records(
    estimates: Sequence[TargetEstimate],
    truth: Mapping[str, np.ndarray] | None,
    calibrated: bool,
) -> list[MeasurementRecord]:
    """Each target's offline estimate as a run's measurement record (truth in H, if given)."""
    records = []
    nan3 = np.full(3, np.nan)
    for step, e in enumerate(estimates):
        ok = e.pairs > 0
        failure = (
            None
            if ok
            else Failure(
                FailureCause.LOST, "estimate", None, f"not in both images of any of {e.seen} pairs"
            )
        )
        true = None if truth is None else truth.get(e.name)
        m = Measurement(
            name=e.name,
            method=Method.STEREO_TRIANGULATION,
            status=Status.OK if ok else Status.FAILED,
            estimate_head_m=e.point_head_m if ok else nan3,
            truth_head_m=nan3 if true is None else np.asarray(true, dtype=float),
            estimate_world_m=nan3,
            truth_world_m=nan3,
            covariance_head_m2=np.full((3, 3), np.nan),
            renders=0,
            servo_residual_px=(),
            details={"pairs": float(e.pairs), "seen": float(e.seen)},
            failure=failure,
            detail="" if failure is None else failure.message,
        )
        records.append(MeasurementRecord(m, "calibrated" if calibrated else "none", step))
    return records


def estimate_payload(
    source: str,
    estimates: Sequence[TargetEstimate],
    pairs: int,
    belief: HeadBelief,
    alpha_e_rad: tuple[float, float],
    truth: Mapping[str, np.ndarray] | None = None,
) -> dict[str, Any]:
    """``headsim estimate``'s results.json (plain data) for a recording's estimates."""
    records = estimate_records(estimates, truth, alpha_e_rad != (0.0, 0.0))
    failures = tuple(
        f"{r.measurement.name}: {r.measurement.status_text}"
        for r in records
        if not r.measurement.ok
    )
    document = EstimateDocument(
        schema=RESULTS_SCHEMA,
        source=source,
        status="ok" if not failures else "failed",
        failures=failures,
        software=software_versions(),
        belief={**asdict(belief), "alpha_e_rad": list(alpha_e_rad)},
        stereo_pairs=pairs,
        measurements=tuple(MeasurementEntry.of(r) for r in records),
        summary=summaries(records),
    )
    payload: dict[str, Any] = encode(document)
    return payload


def results_payload(result: RunOutcome) -> dict[str, Any]:
    """The results.json document (plain data; :func:`headsim.files.write_json_atomic` writes it)."""
    payload: dict[str, Any] = encode(results_document(result))
    return payload


__all__ = [
    "MEASUREMENT_KEYS",
    "RESULTS_KEYS",
    "RESULTS_SCHEMA",
    "EstimateDocument",
    "MeasurementEntry",
    "ResultsDocument",
    "ScenarioRecord",
    "estimate_payload",
    "estimate_records",
    "experiment_block",
    "results_document",
    "results_payload",
    "software_versions",
]
