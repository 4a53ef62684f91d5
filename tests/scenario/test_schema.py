"""The schema of the head and the experiment: presets, overrides, initial directions; a bad field is named with what is allowed."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from headsim.procedures.contract import names
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


def _camera(index: int, field: str):  # type: ignore[no-untyped-def]
    return lambda scenario: getattr(scenario.settings.cameras[index], field)


#: Every imperfection a scenario can set for the head, its cameras, its belief and the
#: calibration's tape: the line, where it must land and the value (unlike every preset's).
IMPERFECTION_KEYS = [
    ("[head]\nbaseline_m = 0.16", lambda s: s.settings.baseline_m, 0.16),
    ("[head]\nneck_d1_m = 0.13", lambda s: s.settings.neck_d1_m, 0.13),
    ("[head]\nneck_a2_m = 0.1", lambda s: s.settings.neck_a2_m, 0.1),
    ("[head]\nencoder_resolution_rad = 1e-4", lambda s: s.settings.encoder_resolution_rad, 1e-4),
    ("[head]\nmount_yaw_rad = [0.01, -0.02]", lambda s: [c.mount_yaw_rad for c in s.settings.cameras], [0.01, -0.02]),
    ("[head]\nmount_pitch_rad = [0.003, -0.004]", lambda s: [c.mount_pitch_rad for c in s.settings.cameras], [0.003, -0.004]),
    ("[head]\nmount_roll_rad = [0.005, -0.006]", lambda s: [c.mount_roll_rad for c in s.settings.cameras], [0.005, -0.006]),
    ("[head]\nbacklash_rad = 5e-4", lambda s: s.settings.backlash_rad, 5e-4),
    ("[head]\ncount_error = true", lambda s: s.settings.count_error, True),
    ("[head]\nrender_offsamples = 2", lambda s: s.settings.render.offsamples, 2),
    ("[head]\nrender_supersample = 3", lambda s: s.settings.render.supersample, 3),
    ("[head]\nsettle = 'physics'", lambda s: s.settle_mode, "physics"),
    ("[cam2]\nkx = 600.0", _camera(1, "kx"), 600.0),
    ("[cam2]\nky = 590.0", _camera(1, "ky"), 590.0),
    ("[cam2]\ncx = 310.0", _camera(1, "cx"), 310.0),
    ("[cam2]\ncy = 250.0", _camera(1, "cy"), 250.0),
    ("[cam2]\nk1 = -0.1", _camera(1, "k1"), -0.1),
    ("[cam2]\nk2 = 0.02", _camera(1, "k2"), 0.02),
    ("[cam2]\nnoise_std = 1.5", _camera(1, "noise_std"), 1.5),
    ("[cam2]\nnodal_offset_m = 0.01", _camera(1, "nodal_offset_m"), 0.01),
    ("[cam2]\nside_offset_m = 0.001", _camera(1, "side_offset_m"), 0.001),
    ("[cam2]\neye_axis_tilt_rad = 0.003", _camera(1, "eye_axis_tilt_rad"), 0.003),
    ("[belief]\nbaseline_m = 0.149", lambda s: s.settings.believed.baseline_m, 0.149),
    ("[belief]\nneck_d1_m = 0.121", lambda s: s.settings.believed.neck_d1_m, 0.121),
    ("[belief]\nneck_a2_m = 0.089", lambda s: s.settings.believed.neck_a2_m, 0.089),
    ("[belief]\nside_offset_m = [0.001, -0.001]", lambda s: s.settings.believed.side_offset_m, (0.001, -0.001)),
    ("[experiment.calibration]\ndepth_noise_m = 0.002", lambda s: s.experiment.calibration.depth_noise_m, 0.002),
    ("[experiment.calibration]\nposition_noise_m = 0.001", lambda s: s.experiment.calibration.position_noise_m, 0.001),
]  # fmt: skip


@pytest.mark.parametrize(
    ("line", "where", "value"),
    IMPERFECTION_KEYS,
    ids=[line.replace("\n", " ").split(" =")[0] for line, _, _ in IMPERFECTION_KEYS],
)
def test_every_imperfection_key_reaches_the_settings(tmp_path: Path, line, where, value) -> None:  # type: ignore[no-untyped-def]
    table, key_line = line.split("\n")
    plain = load_scenario(write_scenario(tmp_path, MINIMAL + table + "\n", "plain.toml"))
    told = load_scenario(write_scenario(tmp_path, MINIMAL + line + "\n", "told.toml"))
    assert where(told) == value
    assert where(plain) != value  # the preset's own value differs: the key moved it
    if table == "[cam2]":  # the other camera keeps its own
        assert _camera(0, key_line.split(" =")[0])(told) != value


BAD = [
    (
        "[head]\nbaseline = 0.1\n",
        "head.baseline: unknown key (allowed: model, mapping, preset, baseline_m, neck_d1_m, neck_a2_m, "
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
        "[experiment.servo]\nwindows = 'off'\n",
        "experiment.servo.windows: must be true or false, got string 'off'",
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


def test_an_unknown_procedure_is_named_with_every_registered_one(tmp_path: Path) -> None:
    path = write_scenario(tmp_path, MINIMAL.replace('"model2"', '"model3"'))
    allowed = ", ".join(names())  # every registered procedure, in their declared ranks
    message = f"{path}: experiment.procedure: unknown value 'model3' (allowed: {allowed})"
    with pytest.raises(ScenarioError, match=re.escape(message)):
        load_scenario(path)


def test_servo_windows_reach_the_servo_and_are_recorded_when_set(tmp_path: Path) -> None:
    from headsim.runs.context import servo_config
    from headsim.scenario.spec import servo_record

    default = load_scenario(write_scenario(tmp_path, MINIMAL))
    assert servo_config(default).windows is True
    assert "windows" not in servo_record(default.experiment.servo)
    path = write_scenario(tmp_path, MINIMAL + "[experiment.servo]\nwindows = false\n", "off.toml")
    off = load_scenario(path)
    assert servo_config(off).windows is False
    assert servo_record(off.experiment.servo)["windows"] is False


@pytest.mark.parametrize(
    ("text", "sources"),
    [
        ("", "design design design design design"),
        ("[head]\nbaseline_m = 0.1512\n", "truth design design design design"),
        ("[head]\nbaseline_m = 0.1512\n[belief]\nneck_d1_m = 0.121\n", "design file design design design"),
        ('[head]\npreset = "realistic"\n', "preset preset preset preset preset"),
        ('[head]\npreset = "realistic"\n[belief]\nside_offset_m = [0.001, 0.0]\n', "preset preset preset preset file"),
    ],
)  # fmt: skip
def test_each_believed_quantity_says_where_it_came_from(tmp_path, text: str, sources: str) -> None:
    scenario = load_scenario(write_scenario(tmp_path, MINIMAL + text))
    assert " ".join(scenario.believed_from.values()) == sources
