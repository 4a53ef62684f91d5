"""A head as real as a bench's (issue 10): belief apart from truth, offsets, joint errors.

Pure-math tests use the exact forward model (headsim.geometry.synthetic) and are strict;
the rest render with real MuJoCo and detect with OpenCV.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np
import pytest

from headsim.estimators import model1, model2
from headsim.estimators.calibration import calibrate_lines_of_sight
from headsim.geometry.camera_model import PinholeCamera, ideal
from headsim.geometry.kinematics import head_to_camera
from headsim.geometry.synthetic import (
    StereoHead,
    effective_initial_direction,
    fixation_angles,
    image_points,
    observe,
)
from headsim.sim import names
from headsim.sim.settings import (
    FINE_RENDERING,
    CameraSettings,
    HeadBelief,
    HeadSettings,
    RenderFidelity,
    SettingsError,
    preset,
)
from headsim.sim.simulator import HeadSim
from headsim.sim.tolerances import REALISTIC_BUDGET
from headsim.vision.markers import find_marker

PAPER1 = PinholeCamera(640, 480, 834.83, 815.42, 303.8, 306.3, -0.38741, 0.0)
PAPER2 = PinholeCamera(640, 480, 850.46, 833.29, 345.1, 197.3, -0.30938, 0.0)


def _points(rng: np.random.Generator, n: int, depth=(0.3, 1.5)) -> np.ndarray:
    z = rng.uniform(*depth, n)
    return np.column_stack([rng.uniform(-0.15, 0.15, n) * z, rng.uniform(-0.1, 0.1, n) * z, z])


# -- pure math: the exact forward model and the estimators ----------------------


@pytest.mark.parametrize("cams", [(ideal(), ideal()), (PAPER1, PAPER2)], ids=["ideal", "paper"])
def test_offset_fixation_puts_the_point_exactly_on_the_goal_columns(cams, rng) -> None:
    head = StereoHead(0.15, *cams, 0.05, -0.02, nodal1=0.02, nodal2=0.015, side1=0.001, side2=-5e-4)
    p = _points(rng, 40)
    fix = fixation_angles(head, p)
    assert fix.valid.all()
    u10, u20 = head.target_columns
    np.testing.assert_allclose(image_points(head, p, 1, fix.alpha1)[:, 0], u10, atol=1e-9)
    np.testing.assert_allclose(image_points(head, p, 2, fix.alpha2)[:, 0], u20, atol=1e-9)


def test_head_to_camera_puts_the_optical_centre_at_its_offset() -> None:
    yaw = 0.2
    nodal, side = 0.02, 0.001
    # The optical centre, axis + side * x_hat + nodal * d, maps to the camera's origin.
    centre = np.array([-0.075 + side * math.cos(yaw) + nodal * math.sin(yaw), 0.0,
                       -side * math.sin(yaw) + nodal * math.cos(yaw)])  # fmt: skip
    np.testing.assert_allclose(
        head_to_camera(centre, 1, yaw, 0.15, nodal=nodal, side=side), 0.0, atol=1e-15
    )


def test_model2_with_calibrated_offsets_is_exact_and_without_them_is_not(rng) -> None:
    cam = PinholeCamera(640, 480, 600.0, 580.0, 319.5, 239.5, 0.0, 0.0)  # u0 at cx: eq. (7) exact
    head = StereoHead(
        0.15, cam, cam, 0.05, -0.02, nodal1=0.02, nodal2=0.015, side1=1e-3, side2=-5e-4
    )
    p = _points(rng, 60)
    obs = observe(head, p, gamma1=0.0, gamma2=0.0)
    args = dict(
        uv10=(319.5, 239.5),
        uv20=(319.5, 239.5),
        alpha_e=head.effective_initial_directions(),
        gamma1=obs.gamma1,
        gamma2=obs.gamma2,
        kx_over_ky=(600 / 580, 600 / 580),
        min_abs_ud=0.0,
    )
    exact = model2(obs.alpha1, obs.alpha2, obs.uv1, obs.uv2, 0.15, **args,
                   los_offset_m=head.line_of_sight_offsets())  # fmt: skip
    assert exact.valid.all()
    np.testing.assert_allclose(exact.positions, p, atol=1e-12)
    plain = model2(obs.alpha1, obs.alpha2, obs.uv1, obs.uv2, 0.15, **args)
    assert np.max(np.abs(plain.positions - p)) > 1e-3


def test_model2_with_offsets_is_exact_in_x_and_z_for_the_paper_cameras(rng) -> None:
    head = StereoHead(0.15, PAPER1, PAPER2, 0.05, -0.02, nodal1=0.02, nodal2=0.02, side1=1e-3)
    p = _points(rng, 50)
    p[:, 1] = 0.0  # in the plane of the optical axes: each image's principal row
    obs = observe(head, p)
    u0 = head.target_columns
    alpha_e, offsets = [], []
    for camera, cam, mount in ((1, PAPER1, 0.05), (2, PAPER2, -0.02)):
        alpha_e.append(effective_initial_direction(camera, mount, cam, u0[camera - 1], cam.cy))
        t = float(cam.column_angle(u0[camera - 1], cam.cy))
        nodal, side = head.offsets(camera)
        offsets.append(side * math.cos(t) - nodal * math.sin(t))
    est = model2(obs.alpha1, obs.alpha2, obs.uv1, obs.uv2, 0.15, uv10=(319.5, 306.3),
                 uv20=(319.5, 197.3), alpha_e=tuple(alpha_e), los_offset_m=tuple(offsets))  # fmt: skip
    np.testing.assert_allclose(est.positions[:, [0, 2]], p[:, [0, 2]], atol=1e-12)


def test_a_forward_offset_alone_changes_nothing_at_the_principal_column(rng) -> None:
    cam = PinholeCamera(640, 480, 600.0, 600.0, 300.0, 250.0, 0.0, 0.0)
    head = StereoHead(0.15, cam, cam, 0.03, 0.01, u10=300.0, u20=300.0, nodal1=0.02, nodal2=0.02)
    assert head.line_of_sight_offsets() == (0.0, 0.0)
    p = _points(rng, 30)
    obs = observe(head, p)
    est = model2(obs.alpha1, obs.alpha2, obs.uv1, obs.uv2, 0.15, uv10=(300.0, 250.0),
                 uv20=(300.0, 250.0), alpha_e=head.effective_initial_directions())  # fmt: skip
    np.testing.assert_allclose(est.positions[:, [0, 2]], p[:, [0, 2]], atol=1e-12)


def test_model1_with_offsets_is_the_crossing_of_the_offset_lines() -> None:
    head = StereoHead(0.15, alpha_e1=0.04, alpha_e2=0.01, side1=1e-3, side2=-2e-3)
    alpha = np.array([0.05, 0.1, 0.2])
    est = model1(alpha, 0.15, alpha_e=(0.04, 0.01), los_offset_m=(1e-3, -2e-3))
    # Both cameras image the estimate on their goal columns at the same eye angle.
    p = est.positions
    u10, u20 = head.target_columns
    np.testing.assert_allclose(image_points(head, p, 1, alpha)[:, 0], u10, atol=1e-9)
    np.testing.assert_allclose(image_points(head, p, 2, alpha)[:, 0], u20, atol=1e-9)


def _los_data(seed: int, noise: float, depth=(0.25, 1.5), baseline: float = 0.1503):
    # The paper's pinholes without distortion: the column angles do not depend on the row.
    cam1 = PinholeCamera(640, 480, 834.83, 815.42, 303.8, 306.3, 0.0, 0.0)
    cam2 = PinholeCamera(640, 480, 850.46, 833.29, 345.1, 197.3, 0.0, 0.0)
    head = StereoHead(baseline, cam1, cam2, 0.05, -0.02, nodal1=0.02, nodal2=0.02, side1=1e-3)
    rng = np.random.default_rng(seed)
    z = rng.uniform(*depth, 60)
    p = np.column_stack([rng.uniform(-0.16, 0.16, 60) * z, np.zeros(60), z])
    obs = observe(head, p, quantised=noise > 0)
    measured = p + rng.normal(0.0, noise, p.shape) if noise > 0 else p
    s1, s2 = head.line_of_sight_offsets()
    # Relative to the believed axes (D = 150 mm): half the baseline error each, outward.
    half_error = (baseline - 0.150) / 2
    truth = np.r_[head.effective_initial_directions(), s1 - half_error, s2 + half_error]
    return head, obs, measured, truth


def test_line_of_sight_fit_recovers_exact_offsets_from_exact_data() -> None:
    _, obs, measured, truth = _los_data(0, 0.0, baseline=0.150)
    fit = calibrate_lines_of_sight(obs.alpha1, obs.alpha2, measured, 0.150,
                                   sigma_position=1e-4, sigma_encoder=1e-5)  # fmt: skip
    assert fit.separable, fit.message
    np.testing.assert_allclose(np.r_[fit.alpha_e, fit.offset_m], truth, atol=1e-12)


def test_a_baseline_error_goes_into_the_effective_baseline() -> None:
    head, obs, measured, _ = _los_data(0, 0.0, baseline=0.1503)
    fit = calibrate_lines_of_sight(obs.alpha1, obs.alpha2, measured, 0.150,
                                   sigma_position=1e-4, sigma_encoder=1e-5)  # fmt: skip
    s1, s2 = head.line_of_sight_offsets()
    # The baseline error's share varies as cos a over the layout: a few micrometres.
    assert abs(fit.effective_baseline_m - (0.1503 - s1 + s2)) < 1e-5


def test_line_of_sight_standard_errors_match_the_scatter_over_seeds() -> None:
    z_scores = []
    for seed in range(30):
        _, obs, measured, truth = _los_data(seed, 1e-3)
        fit = calibrate_lines_of_sight(obs.alpha1, obs.alpha2, measured, 0.150,
                                       sigma_position=1e-3,
                                       sigma_encoder=2 * math.pi / 25600 / math.sqrt(12))  # fmt: skip
        z_scores.append((np.r_[fit.alpha_e, fit.offset_m] - truth) / fit.std_errors)
    spread = np.std(z_scores, axis=0)
    assert np.all((spread > 0.7) & (spread < 1.3)), spread


def test_a_layout_at_one_range_cannot_separate_offset_from_direction() -> None:
    _, obs, measured, _ = _los_data(1, 0.0, depth=(0.5, 0.5 + 1e-3))
    fit = calibrate_lines_of_sight(obs.alpha1, obs.alpha2, measured, 0.150,
                                   sigma_position=1e-3, sigma_encoder=1e-5)  # fmt: skip
    assert not fit.separable
    assert "cannot separate" in fit.message


# -- settings: belief apart from truth --------------------------------------------


def test_belief_is_the_built_head_unless_told_otherwise() -> None:
    settings = HeadSettings(baseline_m=0.2)
    assert settings.believed == HeadBelief(baseline_m=0.2)
    realistic = preset("realistic")
    assert realistic.believed == HeadBelief(nodal_offset_m=(0.02, 0.02))
    assert realistic.baseline_m == pytest.approx(0.150 + REALISTIC_BUDGET["baseline_error_m"][0])
    assert realistic.cameras[0].side_offset_m == REALISTIC_BUDGET["side_offset_m"][0]


@pytest.mark.parametrize(
    ("make", "key"),
    [
        (lambda: HeadBelief(baseline_m=-1.0), "belief.baseline_m"),
        (lambda: HeadBelief(side_offset_m=(0.0, 0.5)), "belief.side_offset_m"),
        (lambda: CameraSettings(nodal_offset_m=0.5), "nodal_offset_m"),
        (lambda: CameraSettings(eye_axis_tilt_rad=1.0), "eye_axis_tilt_rad"),
        (lambda: HeadSettings(backlash_rad=-1e-3), "backlash_rad"),
    ],
)
def test_bad_new_settings_name_their_key_and_range(make, key) -> None:
    with pytest.raises(SettingsError, match=key.replace(".", r"\.") + r" must be"):
        make()


# -- real rendering -----------------------------------------------------------------


def test_optical_centre_offset_moves_the_rendered_marker_as_the_forward_model_says() -> None:
    cam = CameraSettings(nodal_offset_m=0.025, side_offset_m=0.002)
    plain = CameraSettings()
    marker = "marker_red"
    shifts = []
    for cams in ((cam, cam), (plain, plain)):
        with HeadSim("default", HeadSettings(cameras=cams)) as sim:
            sim.set_body_pose(marker, [0.06, 0.35, 0.23])
            sim.move(eye=0.08)
            p_head = sim.position(marker, "head")
            head = StereoHead(0.15, nodal1=cams[0].nodal_offset_m, nodal2=cams[1].nodal_offset_m,
                              side1=cams[0].side_offset_m, side2=cams[1].side_offset_m)  # fmt: skip
            for camera in (1, 2):
                seen = find_marker(sim.render(camera), "red")
                assert seen.found
                model = image_points(head, p_head[None], camera, 0.08)[0]
                assert np.linalg.norm(np.array(seen.uv) - model) < 0.15
                shifts.append(model[0])
    assert abs(shifts[0] - shifts[2]) > 3.0  # the offset moves it by pixels, visibly


def test_backlash_makes_the_true_angle_depend_on_the_approach_direction() -> None:
    backlash = 1e-3
    for mode in ("kinematic", "physics"):
        with HeadSim("default", HeadSettings(backlash_rad=backlash), settle_mode=mode) as sim:
            sim.set_body_pose("marker_red", [0.0, 0.5, 0.21])
            angles, readings, columns = [], [], []
            for start in (-200, 200):
                sim.command_eye_steps(start)
                sim.settle()
                sim.command_eye_steps(0)
                sim.settle()
                angles.append(sim.true_joint_angles()[names.EYE_JOINTS[0]])
                readings.append(sim.eye_encoder_steps())
                columns.append(find_marker(sim.render(1), "red").uv[0])
            assert readings == [0, 0]
            assert angles[1] - angles[0] == pytest.approx(backlash, abs=2e-6)
            assert abs(columns[1] - columns[0]) > 0.3  # 1 mrad at ~580 px/rad


def test_count_error_keeps_the_true_angle_within_the_count_read() -> None:
    settings = HeadSettings(count_error=True, seed=3)
    res = settings.encoder_resolution_rad
    with HeadSim("default", settings) as sim:
        offsets = []
        for steps in range(0, 400, 7):
            sim.command_eye_steps(steps)
            sim.settle()
            assert sim.eye_encoder_steps() == steps
            offsets.append(sim.true_joint_angles()[names.EYE_JOINTS[0]] - steps * res)
    offsets = np.array(offsets) / res
    assert np.all(np.abs(offsets) <= 0.5)
    assert np.std(offsets) > 0.2  # spread over the count, not on it


def test_eye_axis_tilt_leans_the_yaw_axis_forward() -> None:
    tilt = 0.01
    cams = (replace(CameraSettings(), eye_axis_tilt_rad=tilt), CameraSettings())
    with HeadSim("default", HeadSettings(cameras=cams)) as sim:
        sim.move(eye=0.3)
        axis1 = sim.head_from_camera(1)[:3, 2]
        axis2 = sim.head_from_camera(2)[:3, 2]
    # A tilted axis pitches the optical axis as the eye turns; the upright one does not.
    assert abs(axis1[1]) > 1e-3 * 0.3
    assert abs(axis2[1]) < 1e-12


def test_supersampled_rendering_keeps_pixel_centres_and_sharpens_the_centroid() -> None:
    rng = np.random.default_rng(5)
    poses = [
        ([rng.uniform(-0.08, 0.08), rng.uniform(0.45, 0.9), 0.21 + rng.uniform(-0.06, 0.06)],
         float(rng.uniform(-0.04, 0.12)))
        for _ in range(12)
    ]  # fmt: skip
    floors = {}
    for fidelity in (RenderFidelity(4, 1), FINE_RENDERING):
        errors = []
        with HeadSim("default", HeadSettings(render=fidelity)) as sim:
            for target, eye in poses:
                sim.set_body_pose("marker_red", target)
                sim.move(eye=eye)
                seen = find_marker(sim.render(1), "red")
                truth = sim.project(sim.position("marker_red"), 1)[0]
                errors.append(float(np.linalg.norm(np.array(seen.uv) - truth)))
        floors[fidelity.supersample] = np.mean(errors)
        assert max(errors) < 0.15  # a shifted pixel grid would be off by 0.25-0.5 px
    assert floors[2] < floors[1]


def test_bad_render_fidelity_names_its_key() -> None:
    with pytest.raises(SettingsError, match=r"render_supersample must be within \[1, 8\], got 0"):
        RenderFidelity(supersample=0)


# -- scenario files: [belief] and the new keys --------------------------------------

_SCENARIO = """
description = "a test"
{head}
[experiment]
procedure = "model2"

[[scene.targets]]
position_head_m = [0.02, 0.01, 0.6]
"""


def _scenario(tmp_path, head: str):
    from headsim.scenario.loading import load_scenario

    path = tmp_path / "s.toml"
    path.write_text(_SCENARIO.format(head=head))
    return load_scenario(path)


def test_the_belief_differs_from_the_truth_only_where_the_scenario_says(tmp_path) -> None:
    plain = _scenario(tmp_path, "[head]\nbaseline_m = 0.16\n").settings
    assert plain.believed.baseline_m == 0.16  # built as designed
    told = _scenario(
        tmp_path,
        "[head]\nbaseline_m = 0.16\n[belief]\nbaseline_m = 0.15\nside_offset_m = [0.001, 0.0]\n",
    ).settings
    assert told.baseline_m == 0.16 and told.believed.baseline_m == 0.15
    assert told.believed.side_offset_m == (0.001, 0.0)
    assert told.believed.neck_d1_m == told.neck_d1_m  # not said: as built
    realistic = _scenario(tmp_path, '[head]\npreset = "realistic"\n').settings
    assert realistic.believed.baseline_m == 0.150 != realistic.baseline_m


@pytest.mark.parametrize(
    ("head", "field"),
    [
        ("[belief]\nbaseline_m = 2.0\n", "belief.baseline_m"),
        ("[belief]\nnodal_offset_m = [0.02, 0.02]\n", "belief.nodal_offset_m"),
        ("[cam1]\nside_offset_m = 0.1\n", "cam1.side_offset_m"),
        ("[head]\nbacklash_rad = 1.0\n", "head.backlash_rad"),
        ("[head]\nrender_supersample = 0\n", "head.render_supersample"),
    ],
)
def test_a_bad_new_key_in_a_scenario_is_named_with_its_range(tmp_path, head, field) -> None:
    from headsim.scenario.tables import ScenarioError

    with pytest.raises(ScenarioError, match=re.escape(f"{field}:") + ".*allowed"):
        _scenario(tmp_path, head)
