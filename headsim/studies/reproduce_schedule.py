"""Scheduling ``headsim reproduce``'s jobs on a pool: needs first, then the longest path to
the end (in render-times) first."""

from __future__ import annotations

import concurrent.futures as futures
import contextlib
import signal
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from headsim.studies.reproduce_experiments import COSTS, SWEEP_COST
from headsim.studies.reproduce_jobs import JobError, why


@dataclass(frozen=True)
class PlannedJob:
    """A job of the run: what it runs, the jobs it needs, and its arguments from their data."""

    name: str
    run: Callable[..., dict[str, Any]]
    needs: tuple[str, ...]
    args: Callable[[dict[str, dict[str, Any]]], tuple[Any, ...]]


def critical_order(plan: list[PlannedJob]) -> dict[str, float]:
    """Each job's longest path to the end of the run (its cost and its dependents'), in
    render-times: the priority of list scheduling."""
    level: dict[str, float] = {}
    for job in reversed(_topological(plan)):
        after = [level[j.name] for j in plan if job.name in j.needs]
        level[job.name] = COSTS.get(job.name, SWEEP_COST) + max(after, default=0.0)
    return level


def _topological(plan: list[PlannedJob]) -> list[PlannedJob]:
    order: list[PlannedJob] = []
    placed: set[str] = set()
    for _ in range(len(plan)):  # bounded: one job placed per pass at least
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


def schedule(
    pool: futures.Executor,
    workers: int,
    plan: list[PlannedJob],
    finished: Callable[[str, dict[str, Any] | None, str, float], None],
    skipped: Callable[[str, str], None],
    ran: Callable[[str, dict[str, Any]], None],
) -> str:
    """Run ``plan`` on ``pool``, at most ``workers`` jobs at a time: of the jobs whose
    needs are done, the one with the longest path to the end first (the pool
    would otherwise start them in the order they were queued, whatever frees
    first).  A job whose need failed is skipped.  Returns why it ended."""
    level = critical_order(plan)
    waiting = sorted(plan, key=lambda j: -level[j.name])
    done: dict[str, dict[str, Any]] = {}
    failed: set[str] = set()
    running: dict[futures.Future[dict[str, Any]], tuple[str, float]] = {}
    # Ended jobs are reported after the next jobs started: a report (a figure) must
    # not keep a worker idle.
    ended: list[tuple[str, dict[str, Any] | None, str, float]] = []
    for _ in range(2 * len(plan) + 1):  # each pass starts or ends a job at least
        for job in list(waiting):
            missing = next((n for n in job.needs if n in failed), None)
            if missing is not None:
                waiting.remove(job)
                failed.add(job.name)
                skipped(job.name, missing)
            elif len(running) < workers and all(n in done for n in job.needs):
                waiting.remove(job)
                with interrupt_deferred():
                    future = pool.submit(job.run, *job.args(done))
                running[future] = (job.name, time.perf_counter())
        for report in ended:
            finished(*report)
        ended.clear()
        if not running:
            return (
                "every job ended"
                if not waiting
                else f"stuck: {[j.name for j in waiting]} wait for jobs that never ran"
            )
        ready, _ = futures.wait(running, return_when=futures.FIRST_COMPLETED)
        for future in ready:
            name, began = running.pop(future)
            try:
                data = future.result()
            except Exception as err:
                failed.add(name)
                error = str(err) if isinstance(err, JobError) else why(err)
                ended.append((name, None, error, time.perf_counter() - began))
                continue
            ran(name, data)
            done[name] = data
            ended.append((name, data, "", time.perf_counter() - began))
    return "stopped: more passes than jobs allow"
