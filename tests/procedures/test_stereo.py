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
from headsim.head.sim_head import SimHead
from headsim.procedures.stereo import FOCAL_BOUND, HEAD_FRAMES, RMS_BOUND_PX, StereoSpec, calibrate
from headsim.scenario.loading import load_scenario
from headsim.scenario.spec import experiment_record
from headsim.sim.settings import ideal_head
from headsim.sim.simulator import HeadSim
from headsim.stereo.calibration_file import write_stereo_calibration

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
        ("board_seed = -1", "experiment.stereo.board_seed: "),
        ('board_look = "preview"', "experiment.stereo.board_look: "),
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


def test_a_run_without_targets_calibrates_from_the_board_poses_it_is_given(
    tmp_path: Path,
) -> None:
    """A study's Zhang calibration: its own board seed, windowed board looks, no targets.
    The same seed as the scenario's gives the same calibration as the full-frame looks
    (through previews); another seed gives another; both keys are recorded when given."""
    template = 'description = "calibrate only"\nseed = 0\n[experiment]\nprocedure = "stereo"\n'
    template += "[experiment.stereo]\nviews = 6\n{line}\n"
    runs = {}
    for label, line in [
        ("default", ""),
        ("windowed", 'board_look = "windowed"\nboard_seed = 0'),
        ("other", "board_seed = 1"),
    ]:
        path = tmp_path / f"{label}.toml"
        path.write_text(template.format(line=line))
        out = tmp_path / label
        assert main(["--quiet", "run", str(path), "--out", str(out), "--no-progress"]) == 0
        runs[label] = json.loads((out / "results.json").read_text())
    default, windowed, other = runs["default"], runs["windowed"], runs["other"]
    assert default["experiment"]["targets"] == [] and default["experiment"]["head_frames"] == []
    assert windowed["experiment"]["cameras"] == default["experiment"]["cameras"]
    assert default["render_counts"]["overall"]["previews"] == 0
    assert windowed["render_counts"]["overall"]["previews"] > 0
    assert other["experiment"]["cameras"] != default["experiment"]["cameras"]
    assert "board_seed" not in default["scenario"]["experiment"]["block"]
    assert windowed["scenario"]["experiment"]["block"]["board_look"] == "windowed"
    assert other["scenario"]["experiment"]["block"]["board_seed"] == 1


@pytest.fixture(scope="module")
def stored(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A Zhang calibration of the ideal head from eight real board views, as a file."""
    with HeadSim("chessboard", ideal_head()) as sim:
        calibration, _ = calibrate(SimHead(sim), StereoSpec(views=8), seed=0)
    return write_stereo_calibration(tmp_path_factory.mktemp("zhang") / "zhang.json", calibration)


@pytest.mark.parametrize(("look", "renders"), [("", 2), ('look = "once"', 4)])
def test_a_stored_calibration_triangulates_without_calibrating(
    look: str, renders: int, stored: Path, tmp_path: Path
) -> None:
    path = tmp_path / "told.toml"
    path.write_text(SMALL.format(line=f'from = "{stored}"\n{look}'))
    out = tmp_path / "out"
    assert main(["--quiet", "run", str(path), "--out", str(out), "--no-progress"]) == 0
    results = json.loads((out / "results.json").read_text())
    block = results["experiment"]
    assert set(block) == {"procedure", "head_frames", "targets"}
    (target,) = block["targets"]
    error = np.subtract(target["estimate_head_m"], target["truth_head_m"])
    assert target["status"] == "ok" and np.linalg.norm(error) < 1e-3
    # No board view is rendered: each camera looks once for the target.
    assert results["render_counts"]["overall"]["total"] == renders
    assert results["scenario"]["experiment"]["block"]["source"] == str(stored)
    assert "Stereo with a stored calibration (zhang.json)" in (out / "summary.txt").read_text()


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ('from = "missing.json"', "experiment.stereo.from: cannot read"),
        ('from = "bad.json"', "experiment.stereo.from: "),
        ('from = "other.json"', "is not a headsim-stereo-calibration file"),
        ('from = "ok.json"\nviews = 8', "experiment.stereo.views: given with from"),
        ('from = "ok.json"\nlook = "twice"', "experiment.stereo.look: "),
        ('look = "once"', "experiment.stereo.look: given without from"),
    ],
)
def test_a_bad_stored_calibration_is_one_line_naming_its_key(
    line: str, message: str, stored: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "bad.json").write_text("{not json")
    (tmp_path / "other.json").write_text('{"format": "headsim-calibration"}')
    (tmp_path / "ok.json").write_text(stored.read_text())
    path = tmp_path / "stereo.toml"
    path.write_text(SMALL.format(line=line))
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == ExitCode.BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "out").exists()
