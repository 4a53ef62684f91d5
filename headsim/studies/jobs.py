"""The orchestrators' job pool: jobs on spawned local processes or a Dask cluster, each
retried once and a crashed worker survived, and the render workers' pool."""

from __future__ import annotations

import concurrent.futures as cf
import concurrent.futures.process  # noqa: F401  execute() reads cf.process; only a process pool loads it
import importlib
import multiprocessing
import os
import signal
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: Attempts per job: the first and one retry.
ATTEMPTS = 2


def execute(
    jobs: list[Any],
    make_executor: Callable[[], cf.Executor],
    on_record: Callable[[dict[str, Any]], None],
    stop_after: int | None,
    marker_dir: Path | None,
    function: Callable[..., dict[str, Any]],
) -> int:
    """Run ``jobs`` with one retry each; survive a broken pool by building a new one.

    ``function(job, marker_dir)`` runs one job (e.g. :func:`headsim.studies.sweep.run_job`) and
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
                futures[executor.submit(function, job, marker)] = job
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


def map_jobs(
    function: Callable[..., dict[str, Any]],
    jobs: list[Any],
    *,
    workers: int = 1,
    scheduler: str | None = None,
    on_record: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Run ``function(job, None)`` for every job on local processes or Dask; records in job order.

    The same machinery as :func:`headsim.studies.sweep.run_sweep` (spawned processes, one retry,
    crash-proof) for any picklable jobs with ``id`` and ``index``, such as the
    insensitivity study's conditions.
    """
    records: dict[str, dict[str, Any]] = {}

    def keep(record: dict[str, Any]) -> None:
        records[record["id"]] = record
        if on_record is not None:
            on_record(record)

    if scheduler is not None:
        client = dask_client(scheduler)
        try:
            execute(jobs, client.get_executor, keep, None, None, function)
        finally:
            client.close()
    else:
        execute(
            jobs,
            lambda: local_pool(workers),
            keep,
            None,
            None,
            function,
        )
    return [records[job.id] for job in jobs]


def local_pool(workers: int) -> cf.Executor:
    """``workers`` local processes, spawned: EGL in forked children hangs."""
    return cf.ProcessPoolExecutor(
        max_workers=workers, mp_context=multiprocessing.get_context("spawn")
    )


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
