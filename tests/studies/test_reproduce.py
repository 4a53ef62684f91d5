"""``headsim reproduce``: its report, its verdicts, bad input, failures and partial state."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

from headsim.cli import main
from headsim.studies.checks import REPRODUCE_BASELINE
from headsim.studies.checks import reproduce_problems as problems


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


def test_the_ci_check_wants_the_quieter_render_median_as_the_unit() -> None:
    report = {
        "status": "ok",
        "rows": {},
        "wall_s": 16.0,
        "render_before_s": 0.044,
        "render_after_s": 0.033,
        "render_s": 0.033,
        "wall_over_render": 16.0 / 0.033,
    }
    assert problems(report, {"rows": {}}) == []
    flattering = {**report, "render_s": 0.044, "wall_over_render": 16.0 / 0.044}
    assert problems(flattering, {"rows": {}}) == [
        "render unit 0.044 s, not the quieter median 0.033 s"
    ]
    stale = {**report, "wall_over_render": 16.0 / 0.044}
    assert problems(stale, {"rows": {}}) == ["wall ratio is not the wall time over the render unit"]


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


def test_the_command_line_ends_a_run_of_workers_cleanly(tmp_path: Path) -> None:
    # The command line leaves without tearing the interpreter down only when no process
    # was started: after the workers, multiprocessing's finalizers run (without them its
    # resource tracker warns of leaked semaphores on stderr).
    out = tmp_path / "r"
    done = subprocess.run(
        [str(Path(sys.executable).parent / "headsim"), "--quiet", "reproduce", "--fast",
         "--workers", "2", "--out", str(out)],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "Warning" not in done.stderr and "leaked" not in done.stderr, done.stderr
    assert json.loads((out / "report.json").read_text())["status"] == "ok"
    # Both figures, the Tables V/VI one drawn on a thread while the workers ran on.
    for figure in (out / "figures" / "main.png", out / "study" / "tables_v_vi.png"):
        assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", figure


def test_check_reproduce_finds_its_stored_baseline() -> None:
    """CI calls the check without --baseline: its default is the stored file in benchmarks/."""
    assert REPRODUCE_BASELINE.is_file(), REPRODUCE_BASELINE
    assert json.loads(REPRODUCE_BASELINE.read_text())["rows"]
