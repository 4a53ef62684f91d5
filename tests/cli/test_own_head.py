"""A user's own head through the real CLI: an MJCF headsim has never seen (built with
MjSpec, tests/heads_builder.py) and its ``[head.mapping]``.  It runs Model 2 and the
one-step fixation as well as the shipped head nearest it, and every mapping that does
not fit refuses with exit 2 and one line naming the key."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from heads_builder import BuiltHead, build_head

from headsim.cli import main

#: quickstart.toml's cameras, calibration and targets, after the [head] keys.
BODY = """
[cam1]
noise_std = 1.0

[cam2]
noise_std = 1.0

[experiment]
procedure = "{procedure}"

[experiment.calibration]
targets = 20
depth_m = [0.25, 1.2]
position_noise_m = 0.001

[[scene.targets]]
name = "near"
position_head_m = [0.04, 0.02, 0.5]

[[scene.targets]]
name = "far_left"
position_head_m = [-0.12, -0.04, 1.2]

[scene.random_targets]
count = 3
depth_m = [0.5, 1.5]
lateral = 0.12
vertical = 0.06

[fast]
experiment.calibration.targets = 8
scene.random_targets.count = 1
"""
#: The never-seen head's 3-D error RMS (% of depth) may be this many times the shipped
#: head's, plus FLOOR_PCT: a baseline of 0.10 m against 0.15 m (error ~ z / D).
RATIO, FLOOR_PCT = 3.0, 0.05


def scenario(
    directory: Path,
    model: str,
    mapping: str | None,
    procedure: str = "model2",
    name: str = "own.toml",
    cameras: BuiltHead | None = None,
) -> Path:
    """A quickstart-like scenario in ``directory`` on head ``model`` with ``mapping``;
    ``cameras``: a built head whose image size and focal length both cameras take (the
    realistic preset's lens otherwise)."""
    head = f'[head]\nmodel = "{model}"\npreset = "realistic"\n'
    table = "" if mapping is None else f"\n[head.mapping]\n{mapping}"
    body = BODY.format(procedure=procedure)
    if cameras is not None:
        (width, height), f = cameras.resolution, cameras.focal_px
        lens = (
            f"width = {width}\nheight = {height}\nkx = {f}\nky = {f}\n"
            f"cx = {(width - 1) / 2}\ncy = {(height - 1) / 2}\n"
        )
        body = body.replace("[cam1]\n", "[cam1]\n" + lens).replace("[cam2]\n", "[cam2]\n" + lens)
    path = directory / name
    path.write_text('description = "a user\'s head"\nseed = 0\n\n' + head + table + body)
    return path


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> BuiltHead:
    return build_head(tmp_path_factory.mktemp("own") / "head.xml")


def run_ok(path: Path, out: Path) -> dict:
    assert main(["run", str(path), "--fast", "--out", str(out), "--no-progress"]) == 0
    results = json.loads((out / "results.json").read_text())
    assert results["status"] == "ok"
    statuses = [m["status"] for m in results["measurements"]]
    assert len(statuses) == 3 and set(statuses) == {"ok"}, statuses
    return results


@pytest.mark.parametrize("procedure", ["model2", "fixation"])
def test_own_head_measures_as_well_as_the_nearest_shipped_head(
    built: BuiltHead, tmp_path: Path, procedure: str
) -> None:
    own = run_ok(
        scenario(
            built.path.parent, "head.xml", built.toml, procedure, f"own_{procedure}.toml", built
        ),
        tmp_path / "own",
    )
    reference = run_ok(
        scenario(tmp_path, "independent_eyes", None, procedure, "reference.toml"),
        tmp_path / "reference",
    )
    assert own["settings"]["baseline_m"] == pytest.approx(0.1003, abs=1e-12)  # realistic: +0.3 mm
    camera = own["settings"]["cameras"][0]
    assert (camera["width"], camera["height"], camera["kx"]) == (480, 360, 420.0)
    own_pct = own["summary"]["calibrated"]["error_pct_of_depth_rms"]
    reference_pct = reference["summary"]["calibrated"]["error_pct_of_depth_rms"]
    assert 0.0 < own_pct < RATIO * reference_pct + FLOOR_PCT, (own_pct, reference_pct)


def bad_run(path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], key: str) -> str:
    """Exit 2, nothing written, one line on stderr naming ``key``; that line."""
    out = tmp_path / "out"
    assert main(["run", str(path), "--fast", "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"headsim: error: {path}: {key}"), lines[0]
    assert not out.exists()
    return lines[0]


def test_unknown_joint_names_the_key_and_the_model_s_joints(
    built: BuiltHead, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mapping = built.toml.replace('neck_pitch = "nod"', 'neck_pitch = "nope"')
    line = bad_run(
        scenario(built.path.parent, "head.xml", mapping, name="nope.toml"),
        tmp_path,
        capsys,
        "head.mapping.neck_pitch",
    )
    assert "no joint 'nope'" in line and "'nod'" in line and "'port_pan'" in line


def test_unknown_camera_names_the_key_and_the_model_s_cameras(
    built: BuiltHead, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mapping = built.toml.replace('"starboard_imager"]', '"eye_r"]')
    line = bad_run(
        scenario(built.path.parent, "head.xml", mapping, name="camera.toml"),
        tmp_path,
        capsys,
        "head.mapping.cameras[1]",
    )
    assert "no camera 'eye_r'" in line and "'starboard_imager'" in line


def test_camera_on_no_eye_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    head = build_head(tmp_path / "brow.xml", head_camera=True)
    mapping = head.toml.replace('["port_imager"', '["brow_imager"')
    line = bad_run(
        scenario(tmp_path, "brow.xml", mapping, name="brow.toml"),
        tmp_path,
        capsys,
        "head.mapping.cameras[0]",
    )
    assert "'brow_imager' is not on the body of left_eye joint 'port_pan'" in line


@pytest.mark.parametrize(
    ("build", "key", "problem"),
    [
        ({"right_axis_tilt_rad": 0.05}, "head.mapping.right_eye", "0.05 rad from parallel"),
        (
            {"axes_turn_rad": 0.05},
            "head.mapping.left_eye",
            "0.05 rad from perpendicular to the baseline",
        ),
    ],
    ids=["not_parallel", "not_perpendicular"],
)
def test_eye_axes_off_the_method_s_geometry_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], build: dict, key: str, problem: str
) -> None:
    head = build_head(tmp_path / "tilted.xml", **build)
    line = bad_run(scenario(tmp_path, "tilted.xml", head.toml), tmp_path, capsys, key)
    assert problem in line and "within 0.001 rad" in line


def test_model1_needs_a_neck_yaw(
    built: BuiltHead, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mapping = built.toml.replace('neck_yaw = "pan"\n', "")
    line = bad_run(
        scenario(built.path.parent, "head.xml", mapping, "model1", "no_yaw.toml"),
        tmp_path,
        capsys,
        "head.mapping.neck_yaw",
    )
    assert "model1 turns the neck to the midline" in line and "model2" in line


def test_fixation_on_the_paper_head_names_the_procedure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    line = bad_run(
        scenario(tmp_path, "paper", None, "fixation"), tmp_path, capsys, "experiment.procedure"
    )
    assert "couples its eyes" in line and "independent_eyes" in line


def test_missing_model_file_names_head_model(
    built: BuiltHead, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    line = bad_run(
        scenario(tmp_path, "nonexistent.xml", built.toml),
        tmp_path,
        capsys,
        "head.model",
    )
    assert "nonexistent.xml" in line and "independent_eyes" in line


def test_mapping_with_a_shipped_head_is_refused(
    built: BuiltHead, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    line = bad_run(
        scenario(tmp_path, "independent_eyes", built.toml), tmp_path, capsys, "head.mapping"
    )
    assert (
        f"{tmp_path / 'own.toml'}: head.mapping: given for the shipped head 'independent_eyes'"
        in line
    )
    assert "a mapping only with an MJCF file" in line


def test_mjcf_mujoco_cannot_parse_is_one_line_from_the_real_command(
    built: BuiltHead, tmp_path: Path
) -> None:
    (tmp_path / "broken.xml").write_text('<mujoco model="broken"><worldbody><body name="a">')
    path = scenario(tmp_path, "broken.xml", built.toml, name="broken.toml")
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "headsim.cli",
            "run",
            str(path),
            "--fast",
            "--no-progress",
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"headsim: error: {path}: head.model"), lines[0]
    assert "broken.xml" in lines[0] and "an MJCF file MuJoCo compiles" in lines[0]
    assert "XML_ERROR_MISMATCHED_ELEMENT" in lines[0] and "Line number=1" in lines[0]
    assert not (tmp_path / "out").exists()


def test_a_missing_mapping_key_says_what_it_names(
    built: BuiltHead, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mapping = built.toml.replace('neck_pitch = "nod"\n', "")
    line = bad_run(
        scenario(built.path.parent, "head.xml", mapping, name="no_pitch.toml"),
        tmp_path,
        capsys,
        "head.mapping.neck_pitch: missing",
    )
    assert "allowed: the name of a joint in the head's MJCF file" in line
    assert "one line of text" not in line


@pytest.mark.parametrize(
    ("camera", "size"),
    [("", "1 x 1"), ('resolution="16 12" fovy="45"', "16 x 12")],
    ids=["no_resolution", "too_small"],
)
def test_a_camera_without_a_resolution_is_refused_with_what_to_add(
    built: BuiltHead, tmp_path: Path, capsys: pytest.CaptureFixture[str], camera: str, size: str
) -> None:
    # MuJoCo makes a camera without `resolution` 1 x 1 pixels, and takes sensorsize only
    # with it: the head's cameras are given by field of view alone.
    text = built.path.read_text().replace(
        'resolution="480 360" sensorsize="0.0048 0.0036" focalpixel="420 420"', camera
    )
    assert text.count("<camera ") == 2 and 'resolution="480' not in text
    (tmp_path / "small.xml").write_text(text)
    line = bad_run(
        scenario(tmp_path, "small.xml", built.toml, name="small.toml"),
        tmp_path,
        capsys,
        "head.mapping.cameras[0]",
    )
    assert f"camera 'port_imager' is {size} pixels" in line
    assert 'add resolution="WIDTH HEIGHT" to the camera' in line
