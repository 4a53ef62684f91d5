"""The schema of the head and the experiment: presets, overrides, initial directions; a bad field is named with what is allowed."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from headsim.scenario.loading import load_scenario
from headsim.scenario.tables import ScenarioError

from .helpers import MINIMAL, write_scenario


def test_paper_preset_and_overrides_build_the_cameras() -> None:
    scenario = load_scenario("chessboard")
    cam1, cam2 = scenario.settings.cameras
    assert (cam1.kx, cam1.cx, cam1.k1, cam1.noise_std) == (834.83, 303.8, -0.38741, 1.0)
    assert cam2.kx == 850.46
    assert scenario.settings.baseline_m == 0.150


def test_initial_directions_set_the_mount_yaws(tmp_path: Path) -> None:
    from headsim.sim.simulator import HeadSim

    path = write_scenario(
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
        "[experiment.servo]\naverage_fixation = 1\n",
        "experiment.servo.average_fixation: must be true or false, got integer 1",
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
    path = write_scenario(tmp_path, MINIMAL + extra if extra.startswith("[") else extra + MINIMAL)
    with pytest.raises(ScenarioError, match=re.escape(f"{path}: {message}")):
        load_scenario(path)


def test_names_are_unique_and_required_tables_present(tmp_path: Path) -> None:
    twice = MINIMAL + "[[scene.targets]]\nname = 'target_1'\nposition_head_m = [0, 0, 1]\n"
    with pytest.raises(ScenarioError, match=r"scene.targets\[1\].name: 'target_1' is used twice"):
        load_scenario(write_scenario(tmp_path, twice))
    with pytest.raises(ScenarioError, match=r"experiment: missing .allowed: an .experiment. table"):
        load_scenario(write_scenario(tmp_path, 'description = "x"\n'))
    with pytest.raises(ScenarioError, match="description: missing"):
        load_scenario(write_scenario(tmp_path, MINIMAL.replace('description = "a test"', "")))
    calibration = 'description = "c"\n[experiment]\nprocedure = "calibration"\n'
    with pytest.raises(ScenarioError, match=r"experiment.calibration: missing"):
        load_scenario(write_scenario(tmp_path, calibration))
