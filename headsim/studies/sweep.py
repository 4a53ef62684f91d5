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
seed).  ``backend = "batch"`` runs the jobs in chunks instead, each chunk's Model 2
measurements in lockstep (:mod:`headsim.lockstep.runs`: every target of every job a head,
advanced together, drawn through one OpenGL context); each job's calibration, and a job
lockstep does not run (another procedure, a room, a target the classic scan or search
must find), go the classic way, the job's record saying why (``classic_because``)::

    backend = "batch"
    [batch]
    worlds = 32                      # jobs per chunk (default 32)

Jobs are appended to ``DIR/jobs.jsonl`` as they finish, so an interrupted sweep
resumes where it stopped; a job that fails or crashes its process is retried once,
then recorded as failed, and the rest go on.  A job whose scenario the reach check
refuses (its values put a target out of the head's reach) is recorded as
``refused`` with the reason, not retried.  At the
end ``DIR/aggregate.csv``, ``DIR/aggregate.json`` and a plot per swept field.
"""

from __future__ import annotations

import functools
import os
import signal
import time
import traceback
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from headsim.errors import BadInput
from headsim.runs.progress import Counter
from headsim.scenario.tables import TargetRefused
from headsim.studies.jobs import append_record, execute, pools, read_log
from headsim.studies.scenario_jobs import Job, run_row
from headsim.studies.sweep_output import write_aggregate
from headsim.studies.sweep_spec import BatchOptions, SweepSpec

#: Fault injection for tests: job indices (comma-separated) whose process dies.
CRASH_ENV = "HEADSIM_SWEEP_CRASH_JOBS"


def run_job(job: Job, marker_dir: str | None = None, recording: Any = None) -> dict[str, Any]:
    """Run one job in this process; never raises (failures become a record).

    ``marker_dir``: a file named after the job sits there while it runs, so
    that after a crash the sweep knows which jobs were running.  ``recording``:
    a :class:`headsim.runs.rerun_cli.RecordingTarget` for every job (``--rrd DIR``,
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


@dataclass(frozen=True)
class Batch:
    """Jobs run together in one batch session; an id and an index as a job's, for the pool."""

    index: int
    id: str
    jobs: tuple[Job, ...]


def run_batch(batch: Batch, marker_dir: str | None, options: BatchOptions) -> dict[str, Any]:
    """Run ``batch``'s jobs in this process, their Model 2 measurements in lockstep
    (:func:`headsim.lockstep.runs.run_scenarios`; a job lockstep cannot run goes the
    classic way, its record saying why): its record, with each job's under ``records``
    and what lockstep drew under ``rendered``; never raises."""
    marker = Path(marker_dir) / batch.id if marker_dir else None
    if marker is not None:
        marker.touch()
    crash = {int(i) for i in os.environ.get(CRASH_ENV, "").split(",") if i.strip()}
    if any(job.index in crash for job in batch.jobs):
        os.kill(os.getpid(), signal.SIGKILL)
    start = time.perf_counter()
    record: dict[str, Any] = {"id": batch.id, "index": batch.index}
    try:
        from headsim.lockstep.runs import run_scenarios

        loaded: dict[int, Any] = {}
        for row, job in enumerate(batch.jobs):
            try:
                loaded[row] = job.load()
            except Exception:  # the classic path records its refusal or error
                continue
        runs, stats = run_scenarios(list(loaded.values()))
        by_row = dict(zip(loaded, runs, strict=True))
        records = []
        for row, job in enumerate(batch.jobs):
            ran = by_row.get(row)
            if ran is None or isinstance(ran, str):
                job_record = _run_job(job)
                job_record.update(backend="classic", classic_because=ran or "")
            else:
                job_record = {"id": job.id, "index": job.index, "params": job.params}
                job_record.update(run_row(ran))
                job_record.update(backend="batch", wall_s=ran.timing_s.get("total", 0.0))
            records.append(job_record)
        rendered = {"images": stats.images, "calls": 1, "largest": stats.heads}
        record.update(
            status="ok", records=records, rendered={**rendered, "render_s": stats.render_s}
        )
    except Exception as err:  # the lockstep chunk failed: its jobs are recorded as errors
        record.update(status="error", error=f"{type(err).__name__}: {err}")
    finally:
        if marker is not None:
            marker.unlink(missing_ok=True)
    record["wall_s"] = time.perf_counter() - start
    return record


def _batches(jobs: list[Job], size: int, workers: int, attempt: int) -> list[Batch]:
    """``jobs`` in order, cut into batches of at most ``size``, at least one per worker."""
    size = max(1, min(size, -(-len(jobs) // workers)))
    return [
        Batch(i, f"batch{attempt}-{i}", tuple(jobs[start : start + size]))
        for i, start in enumerate(range(0, len(jobs), size))
    ]


def _failed_batch(batch: Batch, record: dict[str, Any]) -> list[dict[str, Any]]:
    """Each of ``batch``'s jobs recorded as failed with it (Warp's error, or a crash)."""
    return [
        {
            "id": job.id,
            "index": job.index,
            "params": job.params,
            "status": record.get("status", "error"),
            "error": record.get("error", ""),
            "backend": "batch",
        }
        for job in batch.jobs
    ]


def _execute_batches(
    jobs: list[Job],
    options: BatchOptions,
    make_executor: Any,
    on_record: Any,
    stop_after: int | None,
    marker_dir: Path | None,
    workers: int,
    rendered: dict[str, float],
) -> int:
    """Run ``jobs`` in batches of ``options.worlds``.  A job that errors, and every job of a
    batch that fails whole (a crash, twice: :func:`~headsim.studies.jobs.execute`), runs
    once more in a batch of its own, so that one bad job takes no other down with it."""
    finished = 0
    tries: dict[str, int] = {}
    rounds = [(_batches(jobs, options.worlds, workers, 1), True)]
    while rounds:
        batches, first = rounds.pop()
        by_id = {b.id: b for b in batches}
        again: list[Job] = []

        def on_batch(record: dict[str, Any]) -> None:
            nonlocal finished
            batch = by_id[record["id"]]  # noqa: B023  called only within this round's execute()
            done = record.get("rendered", {})
            for key in ("images", "calls", "render_s"):
                rendered[key] = rendered.get(key, 0) + done.get(key, 0)
            rendered["largest"] = max(rendered.get("largest", 0), done.get("largest", 0))
            ok = record.get("status") == "ok"
            records = record["records"] if ok else _failed_batch(batch, record)
            for job, job_record in zip(batch.jobs, records, strict=True):
                tries[job.id] = tries.get(job.id, 0) + (1 if ok else record.get("attempts", 1))
                if first and job_record["status"] in ("error", "crashed"):  # noqa: B023
                    again.append(job)  # noqa: B023
                    continue
                job_record["attempts"] = tries[job.id]
                on_record(job_record)
                finished += 1

        limit = None if stop_after is None else -(-stop_after // options.worlds)
        execute(
            batches,
            make_executor,
            on_batch,
            limit,
            marker_dir,
            functools.partial(run_batch, options=options),
        )
        if again and stop_after is None:
            rounds.append((_batches(sorted(again, key=lambda j: j.index), 1, 1, 2), False))
    return finished


def batch_options(spec: SweepSpec, device: str | None = None) -> BatchOptions | None:
    """The batch back-end's options, with ``device`` in place of the file's where given,
    once that device is known to run here (a GPU: Warp must find one); None on the
    classic back-end (which takes no device)."""
    if spec.backend != "batch":
        if device is not None:
            raise BadInput(
                f"device {device!r}: the sweep's backend is {spec.backend!r}; "
                'allowed only with backend = "batch"'
            )
        return None
    from headsim.sim.batch import check_device

    options = spec.batch if device is None else replace(spec.batch, device=device)
    if options.device != "cpu":  # lockstep needs Warp only to say whether a GPU is here
        check_device(options.device)
    return options


def _run_job(job: Job, recording: Any = None) -> dict[str, Any]:
    start = time.perf_counter()
    record: dict[str, Any] = {"id": job.id, "index": job.index, "params": job.params}
    try:
        from headsim.runs.runner import run_scenario

        scenario = job.load()
        if recording is not None:
            from headsim.runs.recording import Recorder
            from headsim.runs.rerun_cli import job_target

            with Recorder(
                None, scenario, target=job_target(recording, job.id), recording=job.id
            ) as recorder:
                result = run_scenario(scenario, [recorder])
        else:
            result = run_scenario(scenario)
        record.update(run_row(result))
    except TargetRefused as err:  # this job's values: its failure, not the sweep file's
        record.update(
            status="refused",
            failures=1,
            failure_reasons=[f"scenario refused: {err.problem}"],
            refusal=err.code,
            error=str(err),
            measurements_ok=0,
            measurements=0,
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
    #: The batch back-end's totals: images, Warp calls, the largest call, seconds rendering.
    rendered: dict[str, float] | None = None

    @property
    def failed(self) -> list[dict[str, Any]]:
        return [r for r in self.records.values() if r.get("status") != "ok"]


def run_sweep(
    spec: SweepSpec,
    out_dir: str | Path,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
    recording: Any = None,
    device: str | None = None,
) -> SweepOutcome:
    """Run the jobs not yet in ``out_dir/jobs.jsonl``; then write the aggregate and plots.

    ``workers``: local processes (spawn start method).  ``scheduler``: a Dask
    scheduler address (``tcp://host:8786``) instead; needs ``headsim[dask]``.
    ``stop_after``: stop after that many jobs (for tests of resuming).
    ``recording``: record every job (:func:`run_job`; the classic back-end only).
    ``device``: the batch back-end's device instead of the file's ``batch.device``.
    """
    options = batch_options(spec, device)  # a missing extra or GPU is said before any job runs
    if options is not None and recording is not None:
        raise BadInput(
            'recording (--rrd, --connect) is not available with backend = "batch"; '
            'allowed: backend = "classic"'
        )
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
        append_record(log, record)
        done[record["id"]] = record
        if bar is not None:
            note = "" if record.get("status") == "ok" else "(this one failed)"
            if record.get("classic_because"):  # the batch back-end ran it the classic way
                note = f"{note} (classic path: {record['classic_because']})".strip()
            bar.update(note=note)

    rendered: dict[str, float] = {}

    def run_all(make_executor: Any, markers: Path | None, pool_size: int) -> int:
        if options is not None:
            return _execute_batches(
                remaining,
                options,
                make_executor,
                on_record,
                stop_after,
                markers,
                pool_size,
                rendered,
            )
        return execute(remaining, make_executor, on_record, stop_after, markers, job_function)

    markers = out / ".running" if scheduler is None else None
    if markers is not None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        markers.mkdir(exist_ok=True)
        for stale in markers.iterdir():
            stale.unlink()
    with pools(workers, scheduler) as (make_pool, slots):
        ran = run_all(make_pool, markers, slots)
    if bar is not None:
        bar.close()
    wall = time.perf_counter() - start
    outcome = SweepOutcome(
        records={job.id: done[job.id] for job in spec.jobs if job.id in done},
        ran=ran,
        skipped=len(spec.jobs) - len(remaining),
        wall_s=wall,
        rendered=None if options is None else rendered,
    )
    if len(outcome.records) == len(spec.jobs):
        outcome.files = write_aggregate(spec, outcome.records, out)
    return outcome
