"""``headsim reproduce``'s jobs: a failing one says why and leaves the render pool working."""

from __future__ import annotations

from pathlib import Path

import pytest

from headsim.studies.jobs import render_pool
from headsim.studies.reproduce_jobs import JobError, scenario_job


def test_a_failing_job_says_why_and_leaves_the_pool_working(tmp_path: Path) -> None:
    # A scenario error cannot be unpickled as such: it must not break the pool.
    missing = str(tmp_path / "missing.json")
    pool = render_pool(1)
    try:
        for _ in range(2):
            job = pool.submit(scenario_job, "chessboard", str(tmp_path), True, None, missing)
            with pytest.raises(JobError, match=r"ScenarioError: .*cannot read"):
                job.result(timeout=300)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
