"""``headsim reproduce``: its report, its verdicts, bad input, failures and partial state."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from check_reproduce import problems

from headsim.cli import main
from headsim.studies.jobs import render_pool
from headsim.studies.reproduce_experiments import STUDY_JOB, JobOutcome
from headsim.studies.reproduce_jobs import JobError, scenario_job
from headsim.studies.reproduce_report import report_sections, report_text
from headsim.studies.reproduce_rows import chessboard_rows, initial_direction_rows, study_rows
from headsim.studies.reproduce_schedule import PlannedJob, critical_order, schedule


def _state(tmp_path: Path, status: str = "ok") -> dict:
    return {
        "status": status,
        "out": tmp_path,
        "fast": True,
        "workers": 2,
        "seed": 0,
        "sweeps": [],
        "render_s": 0.02,
        "wall_s": 30.0,
        "wall_over_render": 1500.0,
    }


CALIBRATION = {
    "head_hash": "ab" * 32,
    "block": {
        "alpha_e_rad": [0.05790, -0.02530],
        "alpha_e_std_rad": [2e-4, 2e-4],
        "fixated": 11,
        "targets": 12,
        "renders": 75,
    },
}
BOARD = {
    "results": {
        "experiment": {
            "side_mean_m": 0.03003,
            "side_std_m": 0.0004,
            "corners": 6,
            "corners_measured": 6,
            "widths_m": [0.0300],
            "heights_m": [0.0301],
        }
    }
}


def test_rows_compare_with_the_papers_figures() -> None:
    rows = initial_direction_rows(CALIBRATION, None)
    assert [r.verdict for r in rows] == ["reproduced", "reproduced"]
    far = {**CALIBRATION, "block": {**CALIBRATION["block"], "alpha_e_rad": [0.0600, -0.0254]}}
    assert initial_direction_rows(far, None)[0].verdict.startswith("differs by +2.2e-03")
    board = chessboard_rows(BOARD)
    assert board[0].ours == "30.030" and board[0].verdict.startswith("reproduced")
    worse = {"results": {"experiment": {**BOARD["results"]["experiment"], "side_mean_m": 0.0306}}}
    assert chessboard_rows(worse)[0].verdict == "not reproduced"
    study = {
        "figures": {
            "tables_v_vi": {"stereo_rms_mm": 0.6, "active_v_known_over_stereo": 1.3},
            "zoom_1_5_paper": {
                "stereo_after_over_before": 300.0,
                "active_fixed_point_after_over_before": 1.4,
            },
        }
    }
    verdicts = [r.verdict for r in study_rows(study)]
    assert verdicts == ["reference", "reproduced", "reproduced (stereo degrades)", "reproduced"]


def test_a_failed_experiment_is_reported_beside_the_others(tmp_path: Path) -> None:
    outcomes = {
        "chessboard": JobOutcome("chessboard", "ok", 12.0, BOARD),
        "tracking": JobOutcome("tracking", "error", 3.0, error="RuntimeError: GL context lost"),
    }
    text = report_text(_state(tmp_path, "failed"), outcomes, CALIBRATION, None)
    assert "**FAILED**: RuntimeError: GL context lost" in text
    assert "| square side, mean, mm (true 30) | 30.3 | 30.030 |" in text
    assert "hash `abababababab`" in text and "seed: 0" in text
    # Not yet run (an interrupted run): said so, the rest readable.
    interrupted = report_text(_state(tmp_path, "interrupted"), outcomes, CALIBRATION, None)
    assert "not run (interrupted)" in interrupted
    sections = {
        name: rows for name, _, rows, _ in report_sections(_state(tmp_path), outcomes, CALIBRATION)
    }
    assert sections["tracking"] is None and sections["chessboard"]


def test_the_ci_check_catches_a_row_no_longer_reproduced() -> None:
    baseline = {"rows": {"chessboard": [{"quantity": "q", "ours": "1", "verdict": "reproduced"}]}}
    same = {"status": "ok", "rows": baseline["rows"]}
    assert problems(same, baseline) == []
    lost = {
        "status": "ok",
        "rows": {"chessboard": [{"quantity": "q", "ours": "9", "verdict": "not reproduced"}]},
    }
    assert problems(lost, baseline) == ["chessboard: q: not reproduced"]
    assert problems({"status": "failed", "rows": {}}, baseline) == [
        "status 'failed', not 'ok'",
        "chessboard: no result",
    ]


def test_bad_input_exits_2_and_writes_nothing(tmp_path: Path, capsys) -> None:
    assert main(["reproduce", "--out", str(tmp_path / "r"), "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err
    afile = tmp_path / "file"
    afile.write_text("x")
    assert main(["reproduce", "--out", str(afile)]) == 2
    assert "not a directory" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


def test_an_interrupted_run_leaves_a_readable_partial_report(tmp_path: Path) -> None:
    out = tmp_path / "r"
    process = subprocess.Popen(
        [str(Path(sys.executable).parent / "headsim"), "reproduce", "--fast", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    report = out / "report.md"
    deadline = time.monotonic() + 120
    while not report.exists() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    assert report.exists(), process.communicate()
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "the report so far is in" in err and "Traceback" not in err
    text = report.read_text()
    assert "status: **interrupted**" in text and "not run (interrupted)" in text
    assert json.loads((out / "report.json").read_text())["status"] == "interrupted"


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

    # calibration (225) -> chessboard (298) is the longest path; zhang (148) and
    # fixed_point (110) lead to tables (115); "broken" fails and its dependent is skipped.
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
    assert level["calibration"] == 225.0 + 298.0
    assert level["zhang"] == 148.0 + 115.0 and level["fixed_point"] == 110.0 + 115.0
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
        "calibration",
        "chessboard",
        "zhang",
        "fixed_point",
        STUDY_JOB,
        "tracking",
    ]
    assert ("broken", True, "RuntimeError: no board") in finished
    assert skipped == [("relative_positioning", "broken")]
    assert "relative_positioning" not in ran and len(finished) == 7


def test_a_plan_with_a_need_that_no_job_meets_is_refused() -> None:
    plan = [PlannedJob("chessboard", _echo, ("calibration",), lambda done: ())]
    with pytest.raises(ValueError, match="unmet or circular needs: \\['chessboard'\\]"):
        critical_order(plan)
