"""The campaigns' job engine: one loop (:func:`run_plan`) over a plan of jobs with needs,
the longest path to the end first, each with its attempts, on a pool that a crashed
worker breaks and a new one replaces; a sweep is a plan without needs (:func:`execute`,
:func:`map_jobs`), ``headsim reproduce`` one with needs.  Also the log a campaign resumes
from (:func:`read_log`, :func:`append_record`) and the render workers' pool."""

from __future__ import annotations

import concurrent.futures as cf
import concurrent.futures.process  # noqa: F401  run_plan() reads cf.process; only a process pool loads it
import contextlib
import functools
import importlib
import json
import multiprocessing
import os
import queue
import signal
import threading
import time
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, TypeVar

from headsim.errors import EnvironmentProblem

#: Attempts per job of a sweep or study: the first and one retry.
ATTEMPTS = 2


@dataclass(frozen=True)
class PlannedJob:
    """A job of a plan: what it runs, the jobs it needs, and its arguments from their data."""

    name: str
    run: Callable[..., dict[str, Any]]
    needs: tuple[str, ...]
    args: Callable[[dict[str, dict[str, Any]]], tuple[Any, ...]]
    #: What it costs, in any unit common to the plan (``headsim reproduce``: render-times).
    cost: float


#: How a job ended: its name, its data (None when it raised), the error, its wall time from
#: submission in s, and the attempts it took.
Ended = Callable[[str, "dict[str, Any] | None", "BaseException | None", float, int], None]


def close_pool(pool: cf.Executor, broken: bool) -> None:
    """Shut ``pool`` down, cancelling what it has not started; a broken pool is not waited for."""
    try:
        pool.shutdown(wait=not broken, cancel_futures=True)
    except TypeError:  # Dask's executor takes no cancel_futures
        pool.shutdown(wait=not broken)


def run_plan(
    plan: list[PlannedJob],
    make_pool: Callable[[], cf.Executor],
    ended: Ended,
    *,
    workers: int | None = None,
    attempts: int = 1,
    retry: Callable[[dict[str, Any]], bool] = lambda data: False,
    markers: Path | None = None,
    stop_after: int | None = None,
    skipped: Callable[[str, str], None] = lambda name, missing: None,
    close: Callable[[cf.Executor, bool], None] | None = close_pool,
) -> str:
    """Run ``plan`` on pools from ``make_pool``; returns why it ended.

    Of the jobs whose needs are done, the one with the longest path to the end starts
    first (a pool would otherwise start them in the order they were queued), at most
    ``workers`` at a time (None: every ready job is queued on the pool at once).  A job
    runs again, up to ``attempts`` in all, when it raised or ``retry(data)`` is true; a
    job whose need failed is skipped.  ``ended`` hears of each job once it last ran,
    after the next jobs started (a report, a figure, must not keep a worker idle).

    A crashed worker breaks a local pool: every job in it fails, a new pool replaces it,
    and only the jobs whose file in ``markers`` shows they were running (the job writes
    it; all of them without ``markers``) count an attempt.  ``stop_after``: stop after
    that many jobs ended.  ``close(pool, broken)`` ends each pool made (None: the
    caller's pool, left open).
    """
    level = critical_order(plan)
    position = {job.name: i for i, job in enumerate(plan)}
    order = lambda job: (-level[job.name], position[job.name])  # noqa: E731
    waiting = sorted(plan, key=order)
    tries = dict.fromkeys(position, 0)
    done: dict[str, dict[str, Any]] = {}
    failed: set[str] = set()
    pool, generation, broken = make_pool(), 0, False
    running: dict[cf.Future[dict[str, Any]], tuple[PlannedJob, float, int]] = {}
    reports: list[tuple[str, dict[str, Any] | None, BaseException | None, float, int]] = []
    finished = 0
    try:
        while True:  # each pass ends a job at least (cf.wait)
            if stop_after is not None and finished + len(reports) >= stop_after:
                for report in reports[: stop_after - finished]:
                    ended(*report)
                return f"stopped after {stop_after} jobs"
            if broken:
                if close is not None:
                    close(pool, True)
                pool, generation, broken = make_pool(), generation + 1, False
            for job in list(waiting):
                lost = next((n for n in job.needs if n in failed), None)
                if lost is not None:
                    waiting.remove(job)
                    failed.add(job.name)
                    skipped(job.name, lost)
                elif (workers is None or len(running) < workers) and all(
                    n in done for n in job.needs
                ):
                    waiting.remove(job)
                    tries[job.name] += 1
                    with interrupt_deferred():
                        future = pool.submit(job.run, *job.args(done))
                    running[future] = (job, time.perf_counter(), generation)
            for report in reports:
                ended(*report)
            finished += len(reports)
            reports.clear()
            if not running:
                return (
                    "every job ended"
                    if not waiting
                    else f"stuck: {[j.name for j in waiting]} wait for jobs that never ran"
                )
            ready, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            for future in sorted(ready, key=lambda f: order(running[f][0])):
                job, began, made_in = running.pop(future)
                data: dict[str, Any] | None = None
                error: BaseException | None = None
                try:
                    data = future.result()
                except Exception as err:  # the job raised, or its worker died
                    error = err
                    if isinstance(err, cf.process.BrokenProcessPool):
                        broken = broken or made_in == generation
                        marker = markers / job.name if markers is not None else None
                        if marker is not None and not marker.exists():
                            tries[job.name] -= 1  # a bystander of another job's crash
                            waiting.append(job)
                            continue
                        if marker is not None:
                            marker.unlink(missing_ok=True)
                if tries[job.name] < attempts and (data is None or retry(data)):
                    waiting.append(job)
                    continue
                if data is None:
                    failed.add(job.name)
                else:
                    done[job.name] = data
                reports.append(
                    (job.name, data, error, time.perf_counter() - began, tries[job.name])
                )
            waiting.sort(key=order)
    finally:
        if close is not None:
            close(pool, broken)


def execute(
    jobs: list[Any],
    make_executor: Callable[[], cf.Executor],
    on_record: Callable[[dict[str, Any]], None],
    stop_after: int | None,
    marker_dir: Path | None,
    function: Callable[..., dict[str, Any]],
) -> int:
    """Run ``jobs`` (each with an ``id`` and an ``index``), a plan without needs, with one
    retry each; returns how many ended.

    ``function(job, marker_dir)`` runs one job (e.g. :func:`headsim.studies.sweep.run_job`)
    and returns its record, a dict with at least ``status``: ``error`` or ``crashed`` is
    retried.  A job that raised, or whose worker died, is recorded as ``crashed``.
    """
    marker = str(marker_dir) if marker_dir is not None else None
    by_id = {job.id: job for job in jobs}
    count = 0

    def record(
        name: str, data: dict[str, Any] | None, error: Any, wall_s: float, tries: int
    ) -> None:
        nonlocal count
        if data is None:
            job = by_id[name]
            data = {
                "id": job.id,
                "index": job.index,
                "params": getattr(job, "params", {}),
                "status": "crashed",
                "error": f"{type(error).__name__}: {error}",
            }
        data["attempts"] = tries
        on_record(data)
        count += 1

    plan = [
        PlannedJob(job.id, function, (), functools.partial(lambda done, j: (j, marker), j=job), 1.0)
        for job in jobs
    ]
    run_plan(
        plan,
        make_executor,
        record,
        attempts=ATTEMPTS,
        retry=lambda data: data.get("status") in ("error", "crashed"),
        markers=marker_dir,
        stop_after=stop_after,
    )
    return count


def map_jobs(
    function: Callable[..., dict[str, Any]],
    jobs: list[Any],
    *,
    workers: int = 1,
    scheduler: str | None = None,
    on_record: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Run ``function(job, None)`` for every job; records in job order.

    One local worker: in this process, one job after the other (an error is raised, not
    retried).  More, or a Dask ``scheduler``: :func:`execute` (spawned processes, one
    retry, crash-proof) for any picklable jobs with ``id`` and ``index``, such as the
    insensitivity study's conditions.
    """
    if workers == 1 and scheduler is None:
        done = []
        for job in jobs:
            done.append(function(job, None))
            if on_record is not None:
                on_record(done[-1])
        return done
    records: dict[str, dict[str, Any]] = {}

    def keep(record: dict[str, Any]) -> None:
        records[record["id"]] = record
        if on_record is not None:
            on_record(record)

    with pools(workers, scheduler) as (make_pool, _):
        execute(jobs, make_pool, keep, None, None, function)
    return [records[job.id] for job in jobs]


# -- resuming ---------------------------------------------------------------------------


def read_log(path: Path) -> dict[str, dict[str, Any]]:
    """Finished jobs from a campaign's log (``jobs.jsonl``: a record per line, as each job
    ended), by id: a campaign resumes with the jobs not in it.  A torn last line (a killed
    writer) is ignored."""
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


def append_record(path: Path, record: dict[str, Any]) -> None:
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


# -- jobs with needs ------------------------------------------------------------------


class JobError(RuntimeError):
    """An experiment failed in its worker; the message says why (picklable, unlike
    some of the errors it stands for: a worker must not break the pool)."""


def plain_errors(job: Callable[..., dict[str, Any]]) -> Callable[..., dict[str, Any]]:
    """``job`` for a worker: any error becomes a :class:`JobError`, and its data says where
    and when it ran (``worker``: pid, start, end, CPU time)."""

    @functools.wraps(job)
    def run(*args: Any) -> dict[str, Any]:
        began, cpu = time.time(), time.process_time()
        try:
            data = job(*args)
        except Exception as err:
            raise JobError(why(err)) from None
        # Where and when it ran (report.json's timeline: the critical path).
        data["worker"] = {
            "pid": os.getpid(),
            "start": began,
            "end": time.time(),
            "cpu_s": time.process_time() - cpu,
        }
        return data

    return run


def job_error(err: BaseException) -> str:
    """What a job's error says: a :class:`JobError`'s message, else :func:`why`."""
    return str(err) if isinstance(err, JobError) else why(err)


def why(err: BaseException) -> str:
    """The last line of ``err``'s report: its type and message."""
    text = "".join(traceback.format_exception_only(type(err), err)).strip()
    return text.splitlines()[-1] if text else repr(err)


def critical_order(plan: list[PlannedJob]) -> dict[str, float]:
    """Each job's longest path to the end of the run (its cost and its dependents'): the
    priority of list scheduling."""
    level: dict[str, float] = {}
    for job in reversed(_topological(plan)):
        after = [level[j.name] for j in plan if job.name in j.needs]
        level[job.name] = job.cost + max(after, default=0.0)
    return level


def _topological(plan: list[PlannedJob]) -> list[PlannedJob]:
    """``plan`` with every job after the jobs it needs (an empty plan: nothing to order)."""
    order: list[PlannedJob] = []
    placed: set[str] = set()
    for _ in range(len(plan)):  # bounded: one job placed per pass at least
        if len(order) == len(plan):
            break
        for job in plan:
            if job.name not in placed and all(n in placed for n in job.needs):
                order.append(job)
                placed.add(job.name)
    if len(order) == len(plan):
        return order
    raise ValueError(
        f"jobs with unmet or circular needs: {sorted({j.name for j in plan} - placed)}"
    )


@contextlib.contextmanager
def interrupt_deferred() -> Iterator[None]:
    """Ctrl-C waits until the block ends (then KeyboardInterrupt): a worker the pool
    is spawning is never left half-started (it would print a traceback and stay
    unknown to the pool).  Only in the main thread; elsewhere it does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda number, frame: caught.append(number))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught:
        raise KeyboardInterrupt


def local_pool(workers: int) -> cf.Executor:
    """``workers`` local processes, spawned: EGL in forked children hangs."""
    return cf.ProcessPoolExecutor(
        max_workers=workers, mp_context=multiprocessing.get_context("spawn")
    )


@contextlib.contextmanager
def pools(workers: int, scheduler: str | None) -> Iterator[tuple[Callable[[], cf.Executor], int]]:
    """Pools of ``workers`` local processes, or of a Dask ``scheduler``'s workers (its
    client closed at the end), and how many jobs they run at once."""
    if scheduler is None:
        yield (lambda: local_pool(workers)), workers
        return
    client = dask_client(scheduler)
    try:
        yield client.get_executor, sum(client.nthreads().values()) or 1
    finally:
        client.close()


def dask_client(scheduler: str) -> Any:
    """A Dask client of ``scheduler`` (``tcp://host:8786``); needs ``headsim[dask]``."""
    try:
        from dask.distributed import Client
    except ImportError as err:
        raise RuntimeError(
            "--scheduler needs Dask: pip install 'headsim[dask]' (dask[distributed])"
        ) from err
    return Client(scheduler)


def _render_threads(workers: int) -> int:
    """llvmpipe threads per worker: the CPUs shared among the workers (at least 1)."""
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    threads = (cpus or 1) // workers
    # One thread: 0, llvmpipe rasterises in the calling thread (no hand-over to a
    # helper thread: ~5 % less CPU per render, the same pixels).
    return 0 if threads <= 1 else threads


def _init_worker(threads: int, preload: tuple[str, ...] = (), ready: Any = None) -> None:
    # Ctrl-C is the parent's to handle: it stops the workers and keeps the report.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # Mesa's llvmpipe renders with one thread per CPU by default: N workers, each
    # with as many threads as the machine has CPUs, would oversubscribe it.  Read
    # when the worker's first OpenGL context is made; a user's own setting is kept.
    os.environ.setdefault("LP_NUM_THREADS", str(threads))
    for name in preload:
        importlib.import_module(name)
    if ready is not None:
        ready.put(os.getpid())


def render_pool(workers: int, preload: tuple[str, ...] = (), ready: Any = None) -> cf.Executor:
    """``workers`` spawned processes that share the CPUs among their renderers and leave
    Ctrl-C to the parent (``headsim reproduce``).

    Each imports the modules ``preload`` as it starts, then puts its pid on the
    queue ``ready`` (made by :func:`spawn_context`); :func:`start_workers` starts them.
    """
    # Spawned, not forked: a fork after OpenGL was used hangs (platform notes).
    return cf.ProcessPoolExecutor(
        max_workers=workers,
        mp_context=spawn_context(),
        initializer=_init_worker,
        initargs=(_render_threads(workers), preload, ready),
    )


def spawn_context() -> Any:
    """The multiprocessing context of the render pool (its queues must be made from it)."""
    return multiprocessing.get_context("spawn")


def start_workers(pool: cf.Executor, workers: int) -> list[cf.Future[int]]:
    """Start ``workers`` processes of ``pool`` now, rather than at its first jobs: a
    spawned pool starts one process per job it is given while none is idle."""
    return [pool.submit(os.getpid) for _ in range(workers)]


#: How long a render pool's workers may take to start and load their modules, s.
WORKERS_START_S = 300.0


class WorkersNotStarted(EnvironmentProblem):
    """The worker processes did not start (exit 3)."""


class _Closing(Protocol):
    def close(self) -> None: ...


Made = TypeVar("Made", bound=_Closing)


def started_render_pool(
    workers: int, preload: tuple[str, ...], meanwhile: Callable[[], Made]
) -> tuple[cf.Executor, Made]:
    """A :func:`render_pool` whose ``workers`` have started and imported ``preload``, and
    what ``meanwhile()`` made while they started (closed if they do not start).

    Returns once every worker is ready and waits, idle; a worker that fails to start, or
    workers not started within :data:`WORKERS_START_S`, raise :class:`WorkersNotStarted`.
    """
    ready = spawn_context().Queue()
    pool = render_pool(workers, preload, ready)
    made = None
    try:
        with interrupt_deferred():
            starting = start_workers(pool, workers)
        made = meanwhile()
        deadline, started = time.monotonic() + WORKERS_START_S, 0
        while started < workers:  # bounded by the deadline
            try:
                ready.get(timeout=0.05)
                started += 1
            except queue.Empty:
                failed = [f.exception() for f in starting if f.done() and f.exception()]
                if failed:
                    raise WorkersNotStarted(f"a worker failed to start: {failed[0]!r}") from None
                if time.monotonic() > deadline:
                    raise WorkersNotStarted(
                        f"{workers - started} of {workers} workers not started "
                        f"within {WORKERS_START_S:.0f} s"
                    ) from None
        return pool, made
    except BaseException:
        stop_pool(pool)
        if made is not None:
            made.close()
        raise


def stop_pool(pool: cf.Executor) -> None:
    """Stop the pool's workers now, whatever they run."""
    pool.shutdown(wait=False, cancel_futures=True)
    terminate_children()


def terminate_children() -> None:
    """Terminate every child process: each is one of the pool's workers, including
    one caught half-started (Ctrl-C while the pool spawned it, which the pool does
    not know of yet, and for which the exit would otherwise wait forever)."""
    for process in multiprocessing.active_children():
        process.terminate()
