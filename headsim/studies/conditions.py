"""The study's conditions (a head, its targets, calibration kept or redone) and running
them, in this process or as jobs of :func:`headsim.studies.jobs.map_jobs`."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from headsim.errors import JobFailed
from headsim.runs.progress import Progress, quiet
from headsim.sim.settings import HeadSettings
from headsim.studies.calibrations import CalibrationCache, Calibrations, calibrate_methods
from headsim.studies.jobs import map_jobs
from headsim.studies.methods import SWEEP_METHODS, StudyConfig
from headsim.studies.target_errors import Summary, TargetError, measure_methods, summarise


@dataclass(frozen=True)
class Condition:
    """A head to measure on and the targets to measure.

    ``group``: which curve or panel it belongs to (e.g. the base head's name);
    ``label``: for people; ``value``: the x of a sweep; ``calibration``:
    "kept" (the methods use the calibrations made on the base head) or
    "redone" (calibrated on ``head``).
    """

    group: str
    label: str
    value: float
    head: HeadSettings
    calibration: str
    targets_head: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        if self.calibration not in ("kept", "redone"):
            raise ValueError(f"calibration must be 'kept' or 'redone', got {self.calibration!r}")


@dataclass(frozen=True)
class ConditionResult:
    condition: Condition
    errors: tuple[TargetError, ...]
    summaries: tuple[Summary, ...]
    seconds: float

    def summary(self, method: str) -> Summary:
        return next(s for s in self.summaries if s.method == method)


@dataclass(frozen=True)
class ConditionJob:
    """One condition to measure, as a job for :func:`headsim.studies.jobs.map_jobs`.

    ``calibrations``: made by the parent for "kept" conditions (shared by
    many); None for "redone" ones, which the worker calibrates itself.
    """

    index: int
    id: str
    condition: Condition
    calibrations: Calibrations | None
    methods: tuple[str, ...]
    config: StudyConfig


def measure_condition(job: ConditionJob, marker_dir: str | None = None) -> dict[str, Any]:
    """Run one condition (in a worker process); the record carries its ConditionResult."""
    start = time.perf_counter()
    calibrations = job.calibrations or calibrate_methods(job.condition.head, job.config)
    errors = measure_methods(
        job.condition.head, calibrations, job.condition.targets_head, job.methods, job.config
    )
    summaries = tuple(summarise(errors, m) for m in job.methods)
    result = ConditionResult(job.condition, tuple(errors), summaries, time.perf_counter() - start)
    return {
        "id": job.id,
        "index": job.index,
        "status": "ok",
        "result": result,
        "calibrations": None if job.calibrations else calibrations,
    }


def run_conditions(
    base: dict[str, HeadSettings],
    conditions: Sequence[Condition],
    cache: CalibrationCache,
    methods: Sequence[str] = SWEEP_METHODS,
    progress: Progress = quiet,
    workers: int = 1,
    scheduler: str | None = None,
) -> list[ConditionResult]:
    """Measure every condition; ``base`` maps each condition's ``group`` to the head calibrated for "kept".

    The conditions run as jobs of :func:`headsim.studies.jobs.map_jobs` (with ``workers``
    > 1 or a Dask ``scheduler`` the "kept" calibrations are made here once and shipped
    with them).
    """
    methods = tuple(methods)
    jobs = []
    for number, condition in enumerate(conditions):
        calibrations = None
        if condition.calibration == "kept":
            calibrations = cache(base[condition.group], f"{condition.group} (base head)")
        elif workers == 1 and scheduler is None:
            calibrations = cache(condition.head, f"{condition.group}: {condition.label}")
        job_id = f"{number}-{condition.group}-{condition.label}-{condition.calibration}"
        jobs.append(ConditionJob(number, job_id, condition, calibrations, methods, cache.config))
    done = 0

    def report(record: dict[str, Any]) -> None:
        nonlocal done
        done += 1
        if record.get("status") != "ok":
            progress(f"[{done}/{len(jobs)}] job {record['id']} failed: {record.get('error')}")
            return
        result = record["result"]
        c = result.condition
        figures = ", ".join(
            f"{m.removeprefix('active_')} {s.rms_pct_depth:.3f}"
            + (f" ({s.failed} failed)" if s.failed else "")
            for m, s in zip(methods, result.summaries, strict=True)
        )
        progress(
            f"[{done}/{len(jobs)}] {c.group}: {c.label} ({c.calibration}): "
            f"RMS % of depth: {figures}  [{result.seconds:.1f} s]"
        )

    records = map_jobs(
        measure_condition, jobs, workers=workers, scheduler=scheduler, on_record=report
    )
    failed = [r for r in records if r.get("status") != "ok"]
    if failed:
        raise JobFailed(f"{len(failed)} condition(s) failed: {failed[0].get('error')}")
    for record in records:
        if record.get("calibrations") is not None:
            cache.add(record["calibrations"])
    return [record["result"] for record in records]
