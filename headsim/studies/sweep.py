"""Parameter sweeps: many scenario runs, on local processes or a Dask cluster.

A sweep file (TOML) names a scenario and the fields to vary::

    description = "Model 2 error against the focal length"
    scenario = "quickstart"          # a name in scenarios/ or a path
    fast = true                      # each job runs the scenario's fast variant

    [grid]                           # every combination of these values
    "cam1.kx" = [600.0, 835.0, 1200.0]
    seed = [0, 1]

    [random]                         # or: a seeded random sample
    count = 20
    seed = 0
    [random.fields]
    "head.baseline_m" = [0.10, 0.20]   # uniform in [low, high]

Each job is one scenario run with those fields set (``seed`` sets the run's
seed).  Jobs are appended to ``DIR/jobs.jsonl`` as they finish, so an
interrupted sweep resumes where it stopped; a job that fails or crashes its
process is retried once, then recorded as failed, and the rest go on.  At the
end ``DIR/aggregate.csv``, ``DIR/aggregate.json`` and a plot per swept field.
"""

from __future__ import annotations

import functools
import json
import os
import signal
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from headsim.run.progress import Counter
from headsim.studies.jobs import dask_client, execute, local_pool
from headsim.studies.sweep_output import write_aggregate
from headsim.studies.sweep_spec import Job, SweepSpec

#: Fault injection for tests: job indices (comma-separated) whose process dies.
CRASH_ENV = "HEADSIM_SWEEP_CRASH_JOBS"


def run_job(job: Job, marker_dir: str | None = None, recording: Any = None) -> dict[str, Any]:
    """Run one job in this process; never raises (failures become a record).

    ``marker_dir``: a file named after the job sits there while it runs, so
    that after a crash the sweep knows which jobs were running.  ``recording``:
    a :class:`headsim.run.rerun_cli.RecordingTarget` for every job (``--rrd DIR``,
    ``--connect``), or None.
    """
    marker = Path(marker_dir) / job.id if marker_dir else None
    if marker is not None:
        marker.touch()
    crash = {int(i) for i in os.environ.get(CRASH_ENV, "").split(",") if i.strip()}
    if job.index in crash:
        os.kill(os.getpid(), signal.SIGKILL)  # a hard crash, as a segfault in a renderer
    try:
        return _run_job(job, recording)
    finally:
        if marker is not None:
            marker.unlink(missing_ok=True)


def _run_job(job: Job, recording: Any = None) -> dict[str, Any]:
    start = time.perf_counter()
    record: dict[str, Any] = {"id": job.id, "index": job.index, "params": job.params}
    try:
        from headsim.run.runner import run_scenario
        from headsim.scenario.loading import load_scenario

        overrides = {k: v for k, v in job.params.items() if k != "seed"}
        scenario = load_scenario(
            job.scenario, fast=job.fast, seed=job.params.get("seed"), overrides=overrides
        )
        if recording is not None:
            from headsim.run.recording import Recorder
            from headsim.run.rerun_cli import job_target

            with Recorder(
                None, scenario, target=job_target(recording, job.id), recording=job.id
            ) as recorder:
                result = run_scenario(scenario, [recorder])
        else:
            result = run_scenario(scenario)
        calibrated = result.calibration is not None
        ok = [r.measurement for r in result.records if r.measurement.ok]
        used = [
            r.measurement
            for r in result.records
            if r.measurement.ok and (r.knowledge != "none" or not calibrated)
        ]
        errors_mm = [1000 * float(np.linalg.norm(m.error_head_m)) for m in used]
        pct = [m.error_pct_of_depth for m in used]
        record.update(
            status="ok" if result.ok else "failed",
            failures=len(result.failures),
            failure_reasons=list(result.failures),
            measurements_ok=len(ok),
            measurements=len(result.records),
            rms_error_pct_depth=float(np.sqrt(np.mean(np.square(pct)))) if pct else None,
            mean_error_mm=float(np.mean(errors_mm)) if errors_mm else None,
            max_error_mm=float(np.max(errors_mm)) if errors_mm else None,
            renders=result.renders.overall.total,
            calibration_max_error_rad=float(
                np.max(np.abs(np.asarray(result.calibration.alpha_e_error_rad)))
            )
            if result.calibration is not None and result.calibration.layout is not None
            else None,
        )
    except Exception as err:  # a job's error must not take the sweep down
        record.update(
            status="error", error=f"{type(err).__name__}: {err}", traceback=traceback.format_exc()
        )
    record["wall_s"] = time.perf_counter() - start
    return record


@dataclass
class SweepOutcome:
    """What a sweep call did: records by job id, counts, and wall time."""

    records: dict[str, dict[str, Any]]
    ran: int
    skipped: int
    wall_s: float
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def failed(self) -> list[dict[str, Any]]:
        return [r for r in self.records.values() if r.get("status") != "ok"]


def read_log(path: Path) -> dict[str, dict[str, Any]]:
    """Finished jobs from ``jobs.jsonl``; a torn last line (a killed writer) is ignored."""
    records: dict[str, dict[str, Any]] = {}
    if not path.exists():
        return records
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            continue
        records[record["id"]] = record
    return records


def _append(path: Path, record: dict[str, Any]) -> None:
    """Append one record as a line, after ending a torn last line if a killed writer left one."""
    line = (json.dumps(record, sort_keys=True) + "\n").encode()
    with path.open("a+b") as handle:
        if handle.tell() > 0:
            handle.seek(-1, os.SEEK_END)
            if handle.read(1) != b"\n":
                line = b"\n" + line
        handle.write(line)
        handle.flush()
        os.fsync(handle.fileno())


def run_sweep(
    spec: SweepSpec,
    out_dir: str | Path,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
    recording: Any = None,
) -> SweepOutcome:
    """Run the jobs not yet in ``out_dir/jobs.jsonl``; then write the aggregate and plots.

    ``workers``: local processes (spawn start method).  ``scheduler``: a Dask
    scheduler address (``tcp://host:8786``) instead; needs ``headsim[dask]``.
    ``stop_after``: stop after that many jobs (for tests of resuming).
    ``recording``: record every job (:func:`run_job`).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    log = out / "jobs.jsonl"
    done = read_log(log)
    remaining = [job for job in spec.jobs if job.id not in done]
    bar = (
        Counter(
            len(remaining),
            unit="jobs",
            name="headsim sweep",
            interval_s=0.0,
            per_minute=True,
            notes_in_lines=True,
        )
        if progress and remaining
        else None
    )
    start = time.perf_counter()
    job_function = functools.partial(run_job, recording=recording) if recording else run_job

    def on_record(record: dict[str, Any]) -> None:
        _append(log, record)
        done[record["id"]] = record
        if bar is not None:
            bar.update(note="" if record.get("status") == "ok" else "(this one failed)")

    if scheduler is not None:
        client = dask_client(scheduler)
        try:
            ran = execute(remaining, client.get_executor, on_record, stop_after, None, job_function)
        finally:
            client.close()
    else:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        markers = out / ".running"
        markers.mkdir(exist_ok=True)
        for stale in markers.iterdir():
            stale.unlink()
        ran = execute(
            remaining,
            lambda: local_pool(workers),
            on_record,
            stop_after,
            markers,
            job_function,
        )
    if bar is not None:
        bar.close()
    wall = time.perf_counter() - start
    outcome = SweepOutcome(
        records={job.id: done[job.id] for job in spec.jobs if job.id in done},
        ran=ran,
        skipped=len(spec.jobs) - len(remaining),
        wall_s=wall,
    )
    if len(outcome.records) == len(spec.jobs):
        outcome.files = write_aggregate(spec, outcome.records, out)
    return outcome
