"""The job engine (studies/jobs.py): one retry per job, records in order, a bound on jobs,
jobs with needs scheduled longest path first, and the renderers' share of the CPUs."""

from __future__ import annotations

import concurrent.futures as cf
import concurrent.futures.process  # noqa: F401  execute() reads cf.process, loaded by its real pools
import os
import subprocess
import sys
import threading
from dataclasses import dataclass
from typing import Any

import pytest

from headsim.studies.catalogue import STUDY_JOB, SWEEP_COST
from headsim.studies.jobs import (
    ATTEMPTS,
    PlannedJob,
    _render_threads,
    critical_order,
    execute,
    job_error,
    render_pool,
    run_plan,
    spawn_context,
    start_workers,
)


@dataclass(frozen=True)
class Job:
    id: str
    index: int
    params: dict[str, Any]


class Flaky:
    """Job 1 fails its first attempt, job 2 every attempt, job 3 raises; the rest succeed."""

    def __init__(self) -> None:
        self.calls: dict[str, int] = {}
        self.lock = threading.Lock()

    def __call__(self, job: Job, marker: str | None) -> dict[str, Any]:
        with self.lock:
            self.calls[job.id] = self.calls.get(job.id, 0) + 1
            call = self.calls[job.id]
        if job.index == 3:
            raise RuntimeError("the worker died")
        failed = job.index == 2 or (job.index == 1 and call == 1)
        return {"id": job.id, "index": job.index, "status": "error" if failed else "ok"}


JOBS = [Job(f"j{i}", i, {"x": i}) for i in range(5)]


def test_every_job_is_retried_once_and_recorded_with_its_attempts() -> None:
    records: list[dict[str, Any]] = []
    flaky = Flaky()
    finished = execute(JOBS, lambda: cf.ThreadPoolExecutor(2), records.append, None, None, flaky)
    assert finished == 5 and ATTEMPTS == 2
    by_id = {r["id"]: r for r in records}
    assert {i: (r["status"], r["attempts"]) for i, r in by_id.items()} == {
        "j0": ("ok", 1),
        "j1": ("ok", 2),
        "j2": ("error", 2),
        "j3": ("crashed", 2),
        "j4": ("ok", 1),
    }
    assert by_id["j3"]["error"] == "RuntimeError: the worker died"
    assert by_id["j3"]["params"] == {"x": 3}
    assert flaky.calls == {"j0": 1, "j1": 2, "j2": 2, "j3": 2, "j4": 1}


def test_stop_after_ends_the_run_after_that_many_records() -> None:
    records: list[dict[str, Any]] = []
    ok = [Job(f"k{i}", i, {}) for i in range(6)]
    finished = execute(
        ok,
        lambda: cf.ThreadPoolExecutor(1),
        records.append,
        2,
        None,
        lambda job, marker: {"id": job.id, "index": job.index, "status": "ok"},
    )
    assert finished == 2 and len(records) == 2


def test_the_renderers_share_the_cpus_and_one_cpu_each_renders_in_the_calling_thread() -> None:
    cpus = len(os.sched_getaffinity(0))
    assert _render_threads(1) == (cpus if cpus > 1 else 0)
    assert _render_threads(2) == (cpus // 2 if cpus // 2 > 1 else 0)
    assert _render_threads(cpus + 1) == 0


_RENDER_DIGEST = """
import hashlib
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
sim = HeadSim("chessboard", HeadSettings())
sim.move(eye=0.05)
print(hashlib.sha256(sim.render(1).tobytes() + sim.render(2).tobytes()).hexdigest())
"""


def test_llvmpipe_without_threads_renders_the_same_pixels() -> None:
    """LP_NUM_THREADS=0 (a worker with one CPU) draws what the threaded renderer draws."""
    digests = []
    for threads in ("0", "2"):
        env = {**os.environ, "LP_NUM_THREADS": threads}
        done = subprocess.run(
            [sys.executable, "-c", _RENDER_DIGEST],
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
            check=True,
        )
        digests.append(done.stdout.strip().splitlines()[-1])
    assert len(digests[0]) == 64 and digests[0] == digests[1]


def test_started_workers_load_their_modules_and_say_so_before_any_job() -> None:
    ready = spawn_context().Queue()
    pool = render_pool(2, ("headsim.sim.settings",), ready)
    try:
        started = start_workers(pool, 2)
        pids = {ready.get(timeout=60), ready.get(timeout=60)}
        assert len(pids) == 2  # one process each, both started before any job ran
        assert {f.result(timeout=60) for f in started} <= pids
        loaded = pool.submit(_loaded, "headsim.sim.settings").result(timeout=60)
        assert loaded
    finally:
        pool.shutdown(cancel_futures=True)


def _loaded(name: str) -> bool:
    import sys

    return name in sys.modules


def _echo(name: str, log: list[str]) -> dict:
    log.append(name)
    if name == "broken":
        raise RuntimeError("no board")
    return {"name": name}


def test_the_scheduler_starts_the_longest_path_first_and_skips_what_lost_a_need() -> None:
    import concurrent.futures as futures

    log: list[str] = []
    job = PlannedJob

    # Costs of the scheduler's own (the shipped ones are measured and move).
    cost = {
        "calibration": 185.0,
        "chessboard": 140.0,
        "fixed_point": 130.0,
        "zhang": 120.0,
        STUDY_JOB: 80.0,
        "tracking": 50.0,
        "relative_positioning": 45.0,
    }

    def make(name: str, needs: tuple[str, ...] = ()) -> PlannedJob:
        return job(name, _echo, needs, lambda done, n=name: (n, log), cost.get(name, SWEEP_COST))

    # calibration (185) -> chessboard (140) is the longest path; fixed_point (130) and
    # zhang (120) lead to tables (80); "broken" fails and its dependent is skipped.
    plan = [
        make("zhang"),
        make("fixed_point"),
        make("tracking", ("calibration",)),
        make(STUDY_JOB, ("calibration", "zhang", "fixed_point")),
        make("calibration"),
        make("chessboard", ("calibration",)),
        make("broken"),
        make("relative_positioning", ("broken",)),
    ]
    level = critical_order(plan)
    assert level["calibration"] == cost["calibration"] + cost["chessboard"]
    assert level["zhang"] == cost["zhang"] + cost[STUDY_JOB]
    assert level["fixed_point"] == cost["fixed_point"] + cost[STUDY_JOB]
    finished, skipped = [], []
    with futures.ThreadPoolExecutor(max_workers=1) as pool:
        ended = run_plan(
            plan,
            lambda: pool,
            lambda name, data, error, wall, tries: finished.append(
                (name, data is None, error and job_error(error))
            ),
            workers=1,
            skipped=lambda name, missing: skipped.append((name, missing)),
            close=None,
        )
        ran = [name for name, lost, _ in finished if not lost]
    assert ended == "every job ended"
    # One worker: each time the ready job with the longest path to the end.
    assert log == [
        "broken",  # SWEEP_COST: as long as a sweep
        "calibration",  # 325 to the end
        "fixed_point",  # 210
        "zhang",  # 200
        "chessboard",  # 140, ready since the calibration
        STUDY_JOB,  # 80, ready once zhang and fixed_point are
        "tracking",  # 50
    ]
    assert ("broken", True, "RuntimeError: no board") in finished
    assert skipped == [("relative_positioning", "broken")]
    assert "relative_positioning" not in ran and len(finished) == 7


def test_an_empty_plan_runs_nothing_and_ends() -> None:
    # A sweep run again once every job is done plans nothing.
    assert critical_order([]) == {}
    finished: list[str] = []
    with cf.ThreadPoolExecutor(max_workers=1) as pool:
        ended = run_plan(
            [], lambda: pool, lambda name, *_: finished.append(name), workers=1, close=None
        )
    assert ended == "every job ended" and finished == []


def test_a_plan_with_a_need_that_no_job_meets_is_refused() -> None:
    plan = [PlannedJob("chessboard", _echo, ("calibration",), lambda done: (), 1.0)]
    with pytest.raises(ValueError, match="unmet or circular needs: \\['chessboard'\\]"):
        critical_order(plan)


@pytest.mark.fast
def test_a_plan_with_needs_retries_its_jobs_and_skips_what_lost_a_need_after_its_attempts() -> None:
    """The one loop's both halves at once: attempts (a sweep's) and needs (reproduce's)."""
    calls: dict[str, int] = {}

    def run(name: str) -> dict[str, Any]:
        calls[name] = calls.get(name, 0) + 1
        if name == "always" or (name == "once" and calls[name] == 1):
            raise RuntimeError(f"{name} failed")
        return {"status": "ok"}

    def make(name: str, needs: tuple[str, ...] = ()) -> PlannedJob:
        return PlannedJob(name, run, needs, lambda done, n=name: (n,), 1.0)

    ended, skipped = [], []
    with cf.ThreadPoolExecutor(max_workers=2) as pool:
        why_ended = run_plan(
            [
                make("once"),
                make("always"),
                make("after_once", ("once",)),
                make("lost", ("always",)),
            ],
            lambda: pool,
            lambda name, data, error, wall, tries: ended.append((name, data is None, tries)),
            workers=2,
            attempts=2,
            skipped=lambda name, missing: skipped.append((name, missing)),
            close=None,
        )
    assert why_ended == "every job ended"
    assert sorted(ended) == [("after_once", False, 1), ("always", True, 2), ("once", False, 2)]
    assert skipped == [("lost", "always")]
    assert calls == {"once": 2, "always": 2, "after_once": 1}
