"""Scheduling ``headsim reproduce``'s jobs: longest path first, needs honoured."""

from __future__ import annotations

import pytest

from headsim.studies.reproduce_experiments import COSTS, STUDY_JOB
from headsim.studies.reproduce_schedule import PlannedJob, critical_order, schedule


def _echo(name: str, log: list[str]) -> dict:
    log.append(name)
    if name == "broken":
        raise RuntimeError("no board")
    return {"name": name}


def test_the_scheduler_starts_the_longest_path_first_and_skips_what_lost_a_need() -> None:
    import concurrent.futures as futures

    log: list[str] = []
    job = PlannedJob

    def make(name: str, needs: tuple[str, ...] = ()) -> PlannedJob:
        return job(name, _echo, needs, lambda done, n=name: (n, log))

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
    cost = COSTS
    assert level["calibration"] == cost["calibration"] + cost["chessboard"]
    assert level["zhang"] == cost["zhang"] + cost[STUDY_JOB]
    assert level["fixed_point"] == cost["fixed_point"] + cost[STUDY_JOB]
    finished, skipped, ran = [], [], []
    with futures.ThreadPoolExecutor(max_workers=1) as pool:
        ended = schedule(
            pool,
            1,
            plan,
            lambda name, data, error, wall: finished.append((name, data is None, error)),
            lambda name, missing: skipped.append((name, missing)),
            lambda name, data: ran.append(name),
        )
    assert ended == "every job ended"
    # One worker: each time the ready job with the longest path to the end.
    assert log == [
        "broken",  # SWEEP_COST: a job without a measured cost counts as long
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


def test_a_plan_with_a_need_that_no_job_meets_is_refused() -> None:
    plan = [PlannedJob("chessboard", _echo, ("calibration",), lambda done: ())]
    with pytest.raises(ValueError, match="unmet or circular needs: \\['chessboard'\\]"):
        critical_order(plan)
