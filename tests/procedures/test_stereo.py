"""The calibrated stereo baseline through ``headsim run``: Zhang's calibration from real
renders beside the simulator's truth, each target triangulated, and its scenario keys'
errors."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rerun.chunk import RrdReader

from headsim.cli import main
from headsim.errors import ExitCode
from headsim.procedures.stereo import FOCAL_BOUND, HEAD_FRAMES, RMS_BOUND_PX
from headsim.scenario.loading import load_scenario
from headsim.scenario.spec import experiment_record

#: A stereo scenario whose ``[experiment.stereo]`` table the bad-key tests fill in.
SMALL = """description = "a bad stereo key"
seed = 0

[experiment]
procedure = "stereo"

[experiment.stereo]
{line}

[[scene.targets]]
position_head_m = [0.0, 0.0, 0.5]
"""


@pytest.fixture(scope="module")
def fast(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The shipped scenario's fast variant, run once: its output folder and recording."""
    root = tmp_path_factory.mktemp("stereo")
    out, rrd = root / "out", root / "stereo.rrd"
    argv = ["run", "stereo", "--fast", "--out", str(out), "--rrd", str(rrd), "--no-progress"]
    assert main(argv) == 0
    return out, rrd


def test_the_calibration_meets_its_acceptance_figure_beside_the_truth(
    fast: tuple[Path, Path],
) -> None:
    results = json.loads((fast[0] / "results.json").read_text())
    block: dict[str, Any] = results["experiment"]
    assert block["procedure"] == "stereo" and results["status"] == "ok"
    assert results["scenario"]["experiment"]["block"]["views"] == 8
    assert block["poses"] == 8 and 5 <= block["views"] <= 8
    assert block["renders"] == 2 * block["poses"]
    assert block["max_rms_px"] <= RMS_BOUND_PX and block["passed"] is True
    assert block["max_abs_focal_error_pct"] <= FOCAL_BOUND * 100
    for camera in block["cameras"]:
        for name in ("kx", "ky"):
            p = camera[name]
            assert abs(p["stereo"] / p["truth"] - 1) <= FOCAL_BOUND
    assert block["baseline_m"] == pytest.approx(block["true_baseline_m"], abs=1e-4)
    assert results["measurements"] == []


def test_each_target_is_triangulated_within_a_millimetre(fast: tuple[Path, Path]) -> None:
    block = json.loads((fast[0] / "results.json").read_text())["experiment"]
    targets = block["targets"]
    assert [t["name"] for t in targets] == ["z400", "z1000", "z1500"]
    for t in targets:
        error = np.subtract(t["estimate_head_m"], t["truth_head_m"])
        assert t["status"] == "ok" and np.linalg.norm(error) < 1e-3
    frames = {f["label"]: f for f in block["head_frames"]}
    assert tuple(frames) == HEAD_FRAMES
    # Cameras assumed parallel to H miss by the mount yaw: tens of mm at 1.5 m.
    assert (
        frames["parallel (yaw 0)"]["max_error_m"] > 0.02 > frames["from extrinsics"]["max_error_m"]
    )
    summary = (fast[0] / "summary.txt").read_text()
    assert "Calibrated stereo (Zhang): " in summary and ": PASS" in summary
    assert "OK: 3 targets triangulated, none failed" in summary


def test_the_recording_holds_each_estimate(fast: tuple[Path, Path]) -> None:
    block = json.loads((fast[0] / "results.json").read_text())["experiment"]
    points = [
        row
        for chunk in RrdReader(fast[1]).stream().filter(content="/world/stereo/estimates")
        for row in chunk.to_record_batch().column("Points3D:positions").to_pylist()
    ]
    assert len(points) == 1
    expected = [t["estimate_world_m"] for t in block["targets"]]
    assert np.allclose(np.array(points[0]), expected, atol=1e-6)


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("views = 3", "experiment.stereo.views: 3 is out of range (allowed: an integer from 5"),
        ("views = 2.5", "experiment.stereo.views: must be an integer"),
        ("distance_m = [1.0, 0.4]", "experiment.stereo.distance_m: [1, 0.4] is reversed"),
        ("max_tilt_rad = 2.0", "experiment.stereo.max_tilt_rad: 2 is out of range"),
        ("refine_intrinsics = 1", "experiment.stereo.refine_intrinsics: must be true or false"),
        ("pattern = [9, 6]", "experiment.stereo.pattern: [9, 6] is not the scene's board"),
        ("board = 1", "experiment.stereo.board: unknown key"),
    ],
)
def test_a_bad_stereo_key_is_one_line_naming_it(
    line: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "stereo.toml"
    path.write_text(SMALL.format(line=line))
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == ExitCode.BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "out").exists()


def test_too_few_board_views_fail_the_run_with_the_reason(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A board 5 m away is too small to be found: no view is kept, no calibration made.
    path = tmp_path / "far.toml"
    path.write_text(SMALL.format(line="views = 5\ndistance_m = [4.9, 5.0]"))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-progress"]) == ExitCode.FAILED
    results = json.loads((out / "results.json").read_text())
    assert results["status"] == "failed" and len(results["failures"]) == 1
    assert results["failures"][0].startswith("stereo calibration: need at least 5 views")
    assert results["experiment"] == {
        "procedure": "stereo",
        "poses": 5,
        "reason": results["failures"][0].removeprefix("stereo calibration: "),
    }
    assert "not calibrated: need at least 5 views" in capsys.readouterr().out


def test_results_json_records_a_procedures_own_table_only_where_it_has_one() -> None:
    stereo = experiment_record(load_scenario("stereo", fast=True).experiment)
    assert stereo["block"] == {
        "views": 8,
        "distance_m": (0.4, 1.0),
        "max_tilt_rad": 0.6,
        "refine_intrinsics": True,
    }
    assert "block" not in experiment_record(load_scenario("quickstart", fast=True).experiment)
