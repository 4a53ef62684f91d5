"""``headsim reproduce``'s jobs: a failing one says why and leaves the render pool working."""

from __future__ import annotations

from pathlib import Path

import pytest

from headsim.studies.jobs import JobError, render_pool
from headsim.studies.reproduce_jobs import scenario_job


def test_a_failing_job_says_why_and_leaves_the_pool_working(tmp_path: Path) -> None:
    # A scenario error cannot be unpickled as such: it must not break the pool.
    missing = str(tmp_path / "missing.json")
    pool = render_pool(1)
    try:
        for _ in range(2):
            after = {"calibration": {"path": missing}}
            job = pool.submit(scenario_job, "chessboard", str(tmp_path), True, None, after)
            with pytest.raises(JobError, match=r"ScenarioError: .*cannot read"):
                job.result(timeout=300)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def test_the_realistic_board_is_the_same_board_on_the_realistic_preset(tmp_path: Path) -> None:
    from headsim.studies.catalogue import REALISTIC_BOARD_JOB
    from headsim.studies.reproduce_rows import chessboard_rows

    data = scenario_job(REALISTIC_BOARD_JOB, str(tmp_path), True, None, {})
    results = data["results"]
    assert results["scenario"]["preset"] == "realistic"
    experiment = results["experiment"]
    assert experiment["corners_measured"] == experiment["corners"] > 0
    assert (tmp_path / "chessboard_realistic" / "results.json").is_file()
    # Its rows stand beside the paper preset's, with the ratio to the paper's rig.
    rows = {r.quantity: r for r in chessboard_rows({**data, "realistic": data})}
    std = rows["square side, std, mm, realistic preset (real tolerances)"]
    assert f"{1e3 * experiment['side_std_m']:.3f} (ours / paper's: " in std.ours
