"""Scenario files: every file in headsim/scenarios/ validates; a bad file says what is wrong and where."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import numpy as np
import pytest

from headsim.cli import main
from headsim.scenario.loading import load_scenario, scenario_files
from headsim.scenario.tables import ScenarioError

FILES = scenario_files()
PAPER_SCENARIOS = ("calibration", "chessboard", "relative_positioning", "tracking")

MINIMAL = """
description = "a test"

[experiment]
procedure = "model2"

[[scene.targets]]
position_head_m = [0.02, 0.01, 0.6]
"""


def _write(tmp_path: Path, text: str, name: str = "bad.toml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_there_is_a_scenario_for_each_experiment_and_a_quick_start() -> None:
    assert {"quickstart", *PAPER_SCENARIOS} <= {p.stem for p in FILES}


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_every_scenario_file_validates_in_both_variants(path: Path) -> None:
    full, fast = load_scenario(path), load_scenario(path, fast=True)
    assert full.description == fast.description and "\n" not in full.description
    assert not full.fast and fast.fast
    assert fast.fixations < full.fixations
    if path.stem in (*PAPER_SCENARIOS, "quickstart"):
        # The paper's cameras, and the initial directions calibrated before measuring.
        assert full.preset == fast.preset == ("realistic" if path.stem == "quickstart" else "paper")
        assert full.experiment.calibration is not None and fast.experiment.calibration is not None


def test_a_scenario_is_found_by_name_and_the_seed_draws_only_the_random_parts() -> None:
    one, other = load_scenario("quickstart"), load_scenario("quickstart", seed=7)
    assert one.seed == 0 and other.seed == other.settings.seed == 7
    explicit = [t for t in one.scene.targets if not t.name.startswith("random")]
    assert explicit == [t for t in other.scene.targets if not t.name.startswith("random")]
    randoms = [t.position_world_m for t in one.scene.targets if t.name.startswith("random")]
    assert randoms and randoms != [
        t.position_world_m for t in other.scene.targets if t.name.startswith("random")
    ]
    assert load_scenario("quickstart", seed=0) == one  # drawn again, the same


def test_paper_preset_and_overrides_build_the_cameras() -> None:
    scenario = load_scenario("chessboard")
    cam1, cam2 = scenario.settings.cameras
    assert (cam1.kx, cam1.cx, cam1.k1, cam1.noise_std) == (834.83, 303.8, -0.38741, 1.0)
    assert cam2.kx == 850.46
    assert scenario.settings.baseline_m == 0.150


def test_initial_directions_set_the_mount_yaws(tmp_path: Path) -> None:
    from headsim.sim.simulator import HeadSim

    path = _write(
        tmp_path,
        MINIMAL + "[head]\ninitial_direction_rad = [0.03, -0.02]\n[cam1]\ncx = 300.0\n",
        "ok.toml",
    )
    scenario = load_scenario(path)
    with HeadSim("default", scenario.settings) as sim:
        assert sim.effective_initial_direction(1) == pytest.approx(0.03, abs=1e-12)
        assert sim.effective_initial_direction(2) == pytest.approx(-0.02, abs=1e-12)


BAD = [
    (
        "[head]\nbaseline = 0.1\n",
        "head.baseline: unknown key (allowed: preset, baseline_m, neck_d1_m, neck_a2_m, "
        "encoder_resolution_rad, initial_direction_rad, mount_yaw_rad, mount_pitch_rad, "
        "mount_roll_rad, settle, backlash_rad, count_error, render_offsamples, render_supersample)",
    ),
    (
        "[head]\nbaseline_m = 'wide'\n",
        "head.baseline_m: must be a number, got string 'wide' (allowed: a number >= 0.01 and <= 1 m; narrower gives no usable vergence)",
    ),
    (
        "[head]\nbaseline_m = 2.0\n",
        "head.baseline_m: 2 is out of range (allowed: a number >= 0.01 and <= 1 m; narrower gives no usable vergence)",
    ),
    (
        "[head]\npreset = 'sony'\n",
        "head.preset: unknown value 'sony' (allowed: ideal, paper, realistic)",
    ),
    (
        "[cam1]\ncx = 700\n",
        "cam1.cx: 700 is out of range (allowed: a number >= 0 and <= 639 px (inside the image))",
    ),
    (
        "[cam2]\nwidth = 640.5\n",
        "cam2.width: must be an integer, got number 640.5 (allowed: an integer from 16 to 4096)",
    ),
    (
        "[cam2]\nnoise_std = -1\n",
        "cam2.noise_std: -1 is out of range (allowed: a number >= 0 and <= 50 grey levels)",
    ),
    (
        "[head]\nmount_yaw_rad = [0.1]\n",
        "head.mount_yaw_rad: must be an array of 2 numbers, got array of 1",
    ),
    (
        "[experiment.calibration]\ntargets = 2\n",
        "experiment.calibration.targets: 2 is out of range (allowed: an integer from 3 to 1000)",
    ),
    (
        "[experiment.servo]\nmax_iterations = true\n",
        "experiment.servo.max_iterations: must be an integer, got boolean True",
    ),
    (
        "[experiment.calibration]\ndepth_m = [0.6, 0.3]\n",
        "experiment.calibration.depth_m: [0.6, 0.3] is empty",
    ),
    ("seed = -1\n", "seed: -1 is out of range (allowed: an integer from 0 to 4294967295)"),
    (
        "colour = 'red'\n",
        "colour: unknown key (allowed: description, seed, head, cam1, cam2, belief, experiment, scene, fast)",
    ),
]


@pytest.mark.parametrize(("extra", "message"), BAD, ids=[m.split(":")[0] for _, m in BAD])
def test_a_bad_field_is_named_with_what_is_allowed(
    tmp_path: Path, extra: str, message: str
) -> None:
    # Top-level keys go first; tables after the minimal file (TOML puts keys in the last table).
    path = _write(tmp_path, MINIMAL + extra if extra.startswith("[") else extra + MINIMAL)
    with pytest.raises(ScenarioError, match=re.escape(f"{path}: {message}")):
        load_scenario(path)


REACH = [
    (
        "[0.0, 0.0, -0.3]",
        "scene.targets[0]: target at [0.000, 0.000, -0.300] m in H is behind or too close to the head "
        "(allowed: z_h from 0.1 to 10 m in front of the head)",
    ),
    (
        "[0.6, 0.0, 0.3]",
        "scene.targets[0]: target at [0.600, 0.000, 0.300] m in H needs an eye angle of 1.153 rad for "
        "camera 1 to fixate it (allowed: targets that both eyes fixate within the eye range [-0.7, 0.7] rad)",
    ),
    (
        "[0.0, 0.7, 1.0]",
        "scene.targets[0]: target at [0.000, 0.700, 1.000] m in H is not seen whole by camera 1 at the "
        "start pose (allowed: a target that both cameras see whole with neck and eyes at 0)",
    ),
    (
        # Camera 2 sees it, camera 1 does not: the procedure could not start step 1.
        "[0.3, 0.0, 0.5]",
        "scene.targets[0]: target at [0.300, 0.000, 0.500] m in H is not seen whole by camera 1 at the "
        "start pose (allowed: a target that both cameras see whole with neck and eyes at 0)",
    ),
]


@pytest.mark.parametrize(
    ("position", "message"), REACH, ids=["behind", "eye range", "out of view", "one camera only"]
)
def test_a_target_out_of_reach_is_refused_without_rendering(
    tmp_path: Path, position: str, message: str
) -> None:
    text = MINIMAL.replace("[0.02, 0.01, 0.6]", position)
    path = _write(tmp_path, text)
    with pytest.raises(ScenarioError, match=re.escape(f"{path}: {message}")):
        load_scenario(path)


def test_other_scenes_check_their_own_things(tmp_path: Path) -> None:
    board = 'description = "b"\n[experiment]\nprocedure = "chessboard"\n[scene.chessboard]\n'
    with pytest.raises(
        ScenarioError, match=r"scene.chessboard.corners: \[48\] has an index out of range"
    ):
        load_scenario(_write(tmp_path, board + "corners = [48]\n"))
    with pytest.raises(ScenarioError, match=r"scene.chessboard: corner 0 at .* is behind"):
        load_scenario(_write(tmp_path, board + "position_head_m = [0.0, 0.0, -1.0]\n"))
    with pytest.raises(
        ScenarioError,
        match=r"scene.chessboard.position_world_m: given together with position_head_m",
    ):
        load_scenario(
            _write(tmp_path, board + "position_head_m = [0, 0, 1]\nposition_world_m = [0, 1, 0]\n")
        )
    track = (
        'description = "t"\n[experiment]\nprocedure = "tracking"\n[scene.moving_target]\n'
        "steps = 3\nduration_s = 1.0\n"
    )
    with pytest.raises(
        ScenarioError,
        match=r"scene.moving_target: the target at t = 1 s at .* needs a neck yaw of -2.783 rad",
    ):
        load_scenario(
            _write(tmp_path, track + "waypoints_world_m = [[0.3, 0.8, 0.2], [0.3, -0.8, 0.2]]\n")
        )
    with pytest.raises(ScenarioError, match=r"scene.moving_target.waypoints_head_m: missing"):
        load_scenario(_write(tmp_path, track))
    blocks = 'description = "r"\n[experiment]\nprocedure = "relative_positioning"\n'
    with pytest.raises(ScenarioError, match=r"scene.objects\[1\].body: 'object_1' is placed twice"):
        load_scenario(
            _write(
                tmp_path,
                blocks + "[[scene.objects]]\nbody = 'object_1'\nposition_head_m = [0, 0, 1]\n" * 2,
            )
        )
    with pytest.raises(
        ScenarioError,
        match=r"scene.targets: unknown key \(allowed: blocks, objects, random_objects\)",
    ):
        load_scenario(_write(tmp_path, blocks + "[[scene.targets]]\nposition_head_m = [0, 0, 1]\n"))


def test_the_fast_table_is_checked_and_named(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL + "[fast]\nexperiment.calibration.targets = 1\n")
    with pytest.raises(
        ScenarioError,
        match=re.escape(f"{path}: fast.experiment.calibration.targets: 1 is out of range"),
    ):
        load_scenario(path)  # the full variant is fine, but both are checked
    path = _write(tmp_path, MINIMAL + "[fast]\ndescription = 'short'\n")
    with pytest.raises(ScenarioError, match=r"fast.description: unknown key"):
        load_scenario(path)


def test_names_are_unique_and_required_tables_present(tmp_path: Path) -> None:
    twice = MINIMAL + "[[scene.targets]]\nname = 'target_1'\nposition_head_m = [0, 0, 1]\n"
    with pytest.raises(ScenarioError, match=r"scene.targets\[1\].name: 'target_1' is used twice"):
        load_scenario(_write(tmp_path, twice))
    with pytest.raises(ScenarioError, match=r"experiment: missing .allowed: an .experiment. table"):
        load_scenario(_write(tmp_path, 'description = "x"\n'))
    with pytest.raises(ScenarioError, match="description: missing"):
        load_scenario(_write(tmp_path, MINIMAL.replace('description = "a test"', "")))
    calibration = 'description = "c"\n[experiment]\nprocedure = "calibration"\n'
    with pytest.raises(ScenarioError, match=r"experiment.calibration: missing"):
        load_scenario(_write(tmp_path, calibration))


def test_a_file_that_is_not_toml_or_not_there_says_so(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match=re.escape(f"{tmp_path / 'bad.toml'}: not valid TOML")):
        load_scenario(_write(tmp_path, "description = \n"))
    with pytest.raises(
        ScenarioError, match=r"no such scenario file .allowed: a .toml path or one of: .*quickstart"
    ):
        load_scenario("kitchen")


def test_run_with_a_bad_file_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _write(tmp_path, MINIMAL.replace("0.6]", "-0.6]"))
    out, rrd = tmp_path / "out", tmp_path / "rec" / "run.rrd"
    assert main(["run", str(path), "--out", str(out), "--rrd", str(rrd)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"headsim: error: {path}: scene.targets[0]: target at")
    assert not out.exists() and not rrd.parent.exists()
    assert main(["run", "quickstart", "--seed", "-3", "--out", str(out)]) == 2
    assert "seed: -3 is out of range" in capsys.readouterr().err
    assert not out.exists()


def test_list_shows_every_scenario_with_its_description(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for path in FILES:
        description = load_scenario(path).description
        assert re.search(rf"^  {path.stem}\s+{re.escape(description)}$", out, re.M)


def test_list_flags_an_invalid_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _write(tmp_path, MINIMAL, "good.toml")
    _write(tmp_path, MINIMAL + "[head]\nbaseline_m = 0\n", "broken.toml")
    assert main(["list", "--dir", str(tmp_path)]) == 2
    out = capsys.readouterr().out
    assert "good" in out and "a test" in out
    assert "broken  INVALID:" in out and "head.baseline_m: 0 is out of range" in out


def test_random_targets_are_drawn_inside_their_spec(tmp_path: Path) -> None:
    text = (
        MINIMAL
        + "[scene.random_targets]\ncount = 50\ndepth_m = [0.5, 0.8]\nlateral = 0.1\nvertical = 0.05\n"
    )
    scenario = load_scenario(_write(tmp_path, text))
    from headsim.geometry.kinematics import world_to_head

    s = scenario.settings
    points = np.array(
        [t.position_world_m for t in scenario.scene.targets if t.name.startswith("random")]
    )
    head = world_to_head(points, 0.0, 0.0, s.neck_d1_m, s.neck_a2_m)
    assert len(points) == 50
    assert np.all((head[:, 2] >= 0.5) & (head[:, 2] <= 0.8))
    assert np.all(np.abs(head[:, 0] / head[:, 2]) <= 0.1)
    assert np.all(np.abs(head[:, 1] / head[:, 2]) <= 0.05)
