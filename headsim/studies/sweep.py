"""Parameter sweeps: many scenario runs, on local processes or a Dask cluster.

A sweep file (TOML) names a scenario and the fields to vary::

    description = "Model 2 error against the focal length"
    scenario = "quickstart"          # a name in headsim/scenarios/ or a path
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

import concurrent.futures as cf
import functools
import hashlib
import io
import itertools
import json
import math
import multiprocessing
import os
import time
import tomllib
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from headsim.errors import BadInput
from headsim.run.progress import Counter
from headsim.run.results import write_bytes_atomic, write_csv_atomic, write_json_atomic

#: Fault injection for tests: job indices (comma-separated) whose process dies.
CRASH_ENV = "HEADSIM_SWEEP_CRASH_JOBS"
#: Attempts per job: the first and one retry.
ATTEMPTS = 2
#: Columns of aggregate.csv after the swept fields.
METRICS = (
    "status",
    "failures",
    "measurements_ok",
    "measurements",
    "rms_error_pct_depth",
    "mean_error_mm",
    "max_error_mm",
    "renders",
    "calibration_max_error_rad",
    "attempts",
)


class SweepError(BadInput, ValueError):
    """A bad sweep file: the message names the file, the field and what is allowed."""

    def __init__(self, source: str, path: str, message: str, allowed: str | None = None) -> None:
        text = f"{source}: {path}: {message}" if path else f"{source}: {message}"
        super().__init__(text + (f" (allowed: {allowed})" if allowed else ""))


@dataclass(frozen=True)
class Job:
    """One scenario run: its position, a stable id, and the fields it sets."""

    index: int
    id: str
    scenario: str
    fast: bool
    params: dict[str, Any]


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep file."""

    path: Path
    description: str
    scenario: str
    fast: bool
    fields: tuple[str, ...]
    jobs: tuple[Job, ...]


def _job_id(scenario: str, fast: bool, params: dict[str, Any]) -> str:
    text = json.dumps({"scenario": scenario, "fast": fast, "params": params}, sort_keys=True)
    return hashlib.sha1(text.encode()).hexdigest()[:12]


def _values(source: str, key: str, value: Any) -> list[Any]:
    if not isinstance(value, list) or not value:
        raise SweepError(
            source, f"grid.{key}", f"must be a non-empty list, got {value!r}", "a list of values"
        )
    return value


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and check a sweep file; every job's scenario is validated before anything runs."""
    from headsim.scenario.schema import ScenarioError, load_scenario, resolve_path

    path = Path(path)
    source = str(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError as err:
        raise SweepError(source, "", "no such sweep file") from err
    except tomllib.TOMLDecodeError as err:
        raise SweepError(source, "", f"not valid TOML: {err}") from err
    allowed_top = ("description", "scenario", "fast", "grid", "random")
    for key in doc:
        if key not in allowed_top:
            raise SweepError(source, key, "unknown key", ", ".join(allowed_top))
    description = doc.get("description")
    if not isinstance(description, str) or not description.strip():
        raise SweepError(source, "description", "missing", "a one-line string")
    scenario = doc.get("scenario")
    if not isinstance(scenario, str):
        raise SweepError(source, "scenario", "missing", "a scenario name or a path to a .toml file")
    candidate = (path.parent / scenario).resolve()
    scenario_path = str(candidate) if candidate.is_file() else scenario
    try:
        scenario_path = str(resolve_path(scenario_path))
    except ScenarioError as err:
        raise SweepError(source, "scenario", str(err)) from err
    fast = doc.get("fast", False)
    if not isinstance(fast, bool):
        raise SweepError(source, "fast", f"must be true or false, got {fast!r}", "true, false")
    if ("grid" in doc) == ("random" in doc):
        raise SweepError(source, "", "needs exactly one of [grid] and [random]", "[grid], [random]")
    if "grid" in doc:
        grid = doc["grid"]
        if not isinstance(grid, dict) or not grid:
            raise SweepError(source, "grid", "must be a table of field = [values]")
        fields = tuple(grid)
        combos = itertools.product(*(_values(source, k, grid[k]) for k in fields))
        params_list = [dict(zip(fields, combo, strict=True)) for combo in combos]
    else:
        params_list, fields = _random_params(source, doc["random"])
    jobs = []
    for index, params in enumerate(params_list):
        overrides = {k: v for k, v in params.items() if k != "seed"}
        seed = params.get("seed")
        try:
            load_scenario(scenario_path, fast=fast, seed=seed, overrides=overrides)
        except ScenarioError as err:
            raise SweepError(source, f"job {index} {params}", str(err)) from err
        jobs.append(Job(index, _job_id(scenario_path, fast, params), scenario_path, fast, params))
    return SweepSpec(path, description.strip(), scenario_path, fast, fields, tuple(jobs))


def _random_params(source: str, table: Any) -> tuple[list[dict[str, Any]], tuple[str, ...]]:
    if not isinstance(table, dict):
        raise SweepError(source, "random", "must be a table")
    for key in table:
        if key not in ("count", "seed", "fields"):
            raise SweepError(source, f"random.{key}", "unknown key", "count, seed, fields")
    count, seed = table.get("count"), table.get("seed", 0)
    if not isinstance(count, int) or not 1 <= count <= 100_000:
        raise SweepError(
            source, "random.count", f"{count!r} is not allowed", "an integer from 1 to 100000"
        )
    if not isinstance(seed, int) or seed < 0:
        raise SweepError(source, "random.seed", f"{seed!r} is not allowed", "an integer >= 0")
    fields = table.get("fields")
    if not isinstance(fields, dict) or not fields:
        raise SweepError(source, "random.fields", "missing", "a table of field = [low, high]")
    rng = np.random.default_rng(seed)
    columns = {}
    for key, bounds in fields.items():
        ok = (
            isinstance(bounds, list)
            and len(bounds) == 2
            and all(isinstance(b, int | float) and math.isfinite(b) for b in bounds)
            and bounds[0] <= bounds[1]
        )
        if not ok:
            raise SweepError(
                source,
                f"random.fields.{key}",
                f"{bounds!r} is not a range",
                "[low, high] with low <= high",
            )
        if key == "seed":
            columns[key] = [
                int(v) for v in rng.integers(int(bounds[0]), int(bounds[1]) + 1, size=count)
            ]
        else:
            columns[key] = [float(v) for v in rng.uniform(bounds[0], bounds[1], size=count)]
    names = tuple(fields)
    return [{k: columns[k][i] for k in names} for i in range(count)], names


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
        os._exit(86)  # a hard crash, as a segfault in a renderer would be
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
        from headsim.scenario.schema import load_scenario

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
            renders=int(result.renders["total"]),
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


def _execute(
    jobs: list[Any],
    make_executor: Callable[[], cf.Executor],
    on_record: Callable[[dict[str, Any]], None],
    stop_after: int | None,
    marker_dir: Path | None = None,
    function: Callable[..., dict[str, Any]] | None = None,
) -> int:
    """Run ``jobs`` with one retry each; survive a broken pool by building a new one.

    ``function(job, marker_dir)`` runs one job (default :func:`run_job`) and
    returns its record, a dict with at least ``status``; a job is anything
    with an ``id`` and an ``index``.

    When a local pool breaks, every job still queued in it fails with it; only
    those whose marker shows they were running count an attempt.
    """
    attempts = dict.fromkeys((job.id for job in jobs), 0)
    queue = list(jobs)
    finished = 0
    while queue:
        executor = make_executor()
        broken = False
        try:
            futures = {}
            for job in queue:
                attempts[job.id] += 1
                marker = str(marker_dir) if marker_dir is not None else None
                futures[executor.submit(function or run_job, job, marker)] = job
            queue = []
            for future in cf.as_completed(futures):
                job = futures[future]
                try:
                    record = future.result()
                except Exception as err:  # the worker died (BrokenProcessPool, KilledWorker, ...)
                    if isinstance(err, cf.process.BrokenProcessPool):
                        broken = True
                        was_running = True
                        if marker_dir is not None:
                            was_running = (marker_dir / job.id).exists()
                            (marker_dir / job.id).unlink(missing_ok=True)
                        if not was_running:  # an innocent bystander of another job's crash
                            attempts[job.id] -= 1
                            queue.append(job)
                            continue
                    record = {
                        "id": job.id,
                        "index": job.index,
                        "params": getattr(job, "params", {}),
                        "status": "crashed",
                        "error": f"{type(err).__name__}: {err}",
                    }
                if record.get("status") in ("error", "crashed") and attempts[job.id] < ATTEMPTS:
                    queue.append(job)
                    continue
                record["attempts"] = attempts[job.id]
                on_record(record)
                finished += 1
                if stop_after is not None and finished >= stop_after:
                    for other in futures:
                        other.cancel()
                    return finished
        finally:
            try:
                executor.shutdown(wait=not broken, cancel_futures=True)
            except TypeError:  # Dask's executor takes no cancel_futures
                executor.shutdown(wait=not broken)
        queue.sort(key=lambda job: job.index)
    return finished


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
        client = _dask_client(scheduler)
        try:
            ran = _execute(
                remaining, client.get_executor, on_record, stop_after, None, job_function
            )
        finally:
            client.close()
    else:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        context = multiprocessing.get_context("spawn")  # EGL in forked children hangs
        markers = out / ".running"
        markers.mkdir(exist_ok=True)
        for stale in markers.iterdir():
            stale.unlink()
        ran = _execute(
            remaining,
            lambda: cf.ProcessPoolExecutor(max_workers=workers, mp_context=context),
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


def map_jobs(
    function: Callable[..., dict[str, Any]],
    jobs: list[Any],
    *,
    workers: int = 1,
    scheduler: str | None = None,
    on_record: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Run ``function(job, None)`` for every job on local processes or Dask; records in job order.

    The same machinery as :func:`run_sweep` (spawned processes, one retry,
    crash-proof) for any picklable jobs with ``id`` and ``index``, such as the
    insensitivity study's conditions.
    """
    records: dict[str, dict[str, Any]] = {}

    def keep(record: dict[str, Any]) -> None:
        records[record["id"]] = record
        if on_record is not None:
            on_record(record)

    if scheduler is not None:
        client = _dask_client(scheduler)
        try:
            _execute(jobs, client.get_executor, keep, None, None, function)
        finally:
            client.close()
    else:
        context = multiprocessing.get_context("spawn")
        _execute(
            jobs,
            lambda: cf.ProcessPoolExecutor(max_workers=workers, mp_context=context),
            keep,
            None,
            None,
            function,
        )
    return [records[job.id] for job in jobs]


def _dask_client(scheduler: str) -> Any:
    try:
        from dask.distributed import Client
    except ImportError as err:
        raise RuntimeError(
            "--scheduler needs Dask: pip install 'headsim[dask]' (dask[distributed])"
        ) from err
    return Client(scheduler)


def aggregate_rows(spec: SweepSpec, records: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per job, in job order: the swept fields, then ``METRICS``."""
    rows = []
    for job in spec.jobs:
        record = records[job.id]
        row = {"job": job.index, **{f: job.params.get(f) for f in spec.fields}}
        row.update({m: record.get(m) for m in METRICS})
        rows.append(row)
    return rows


def write_aggregate(
    spec: SweepSpec, records: dict[str, dict[str, Any]], out: Path
) -> dict[str, Path]:
    """aggregate.csv, aggregate.json and one PNG per numeric swept field."""
    rows = aggregate_rows(spec, records)
    files = {"csv": out / "aggregate.csv", "json": out / "aggregate.json"}
    write_csv_atomic(files["csv"], rows)
    write_json_atomic(
        files["json"], {"sweep": spec.description, "scenario": spec.scenario, "rows": rows}
    )
    for name in spec.fields:
        if name == "seed":  # an error against the seed says nothing
            continue
        png = plot_metric(
            rows, name, "rms_error_pct_depth", out / f"error_vs_{_slug(name)}.png", spec.description
        )
        if png is not None:
            files[f"plot {name}"] = png
    return files


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in name)


def plot_metric(rows: list[dict[str, Any]], x: str, y: str, path: Path, title: str) -> Path | None:
    """Scatter of ``y`` against ``x`` with the mean per x value; None if x is not numeric."""
    points = [
        (row[x], row[y])
        for row in rows
        if isinstance(row.get(x), int | float) and isinstance(row.get(y), int | float)
    ]
    if len(points) < 2:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs, ys = np.array(points, dtype=float).T
    fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
    ax.scatter(xs, ys, s=18, alpha=0.6, label="jobs")
    unique = np.unique(xs)
    if len(unique) < len(xs):
        ax.plot(unique, [ys[xs == u].mean() for u in unique], "o-", color="C3", label="mean")
    ax.set_xlabel(x)
    ax.set_ylabel("3-D error RMS, % of depth" if y == "rms_error_pct_depth" else y)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    plt.close(fig)
    write_bytes_atomic(path, buffer.getvalue())
    return path


def _cell(value: Any) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def summary_table(spec: SweepSpec, records: Iterable[dict[str, Any]]) -> str:
    """A readable table of the jobs."""
    lines = [
        "  ".join(
            [
                f"{'job':>4s}",
                *(f"{f:>16s}" for f in spec.fields),
                f"{'status':>8s}",
                f"{'err %z':>8s}",
                f"{'renders':>7s}",
            ]
        )
    ]
    by_index = sorted(records, key=lambda r: r["index"])
    for r in by_index:
        values = [f"{_cell(r['params'].get(f)):>16s}" for f in spec.fields]
        err = r.get("rms_error_pct_depth")
        lines.append(
            "  ".join(
                [
                    f"{r['index']:4d}",
                    *values,
                    f"{r.get('status', '?'):>8s}",
                    f"{err:8.3f}" if err is not None else f"{'-':>8s}",
                    f"{r.get('renders', '-')!s:>7s}",
                ]
            )
        )
    return "\n".join(lines)
