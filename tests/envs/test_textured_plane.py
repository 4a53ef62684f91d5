"""headsim/Fixate-v0 with scene="textured_plane": seeded planes, the true vergence error,
Gymnasium's checker, the image-based vergence policy, bad options."""

from __future__ import annotations

import ast
import math
import warnings
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import headsim.envs
import headsim.envs.policies
from headsim.envs.fixate import FixateEnv, plane_texture_px
from headsim.envs.policies import VergencePolicy
from headsim.envs.vector import FixateVectorEnv
from headsim.sim.render import release_renderers
from headsim.sim.settings import SettingsError
from headsim.vision.correspondence import MatchStatus

ID = headsim.envs.FIXATE_ID
SMALL: dict[str, Any] = {"scene": "textured_plane", "width": 64, "height": 48}
#: The eye motor at a tenth of its speed limit, neck still: eyes turn inward (converge).
CONVERGE = np.array([0.0, 0.0, 0.1], np.float32)


def test_plane_env_passes_gymnasiums_checker_and_observations_are_the_images() -> None:
    env = gymnasium.make(ID, **SMALL)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)  # also resets twice with one seed and compares
    assert [str(w.message) for w in caught] == []
    obs, info = env.reset(seed=1)
    assert obs in env.observation_space
    assert obs["cam1"].shape == obs["cam2"].shape == (48, 64, 3)
    space = env.observation_space
    assert isinstance(space, gymnasium.spaces.Dict)
    assert space["cam1"].shape == space["cam2"].shape == (48, 64, 3)
    # Textured, not blank: the plane fills both images.
    assert min(float(obs[c].std()) for c in ("cam1", "cam2")) > 5.0
    assert {"vergence_error_deg", "depth_m", "texture_seed", "truth_world_m"} <= set(info)
    assert "offsets_px" not in info  # no marker to measure
    env.close()


def test_reset_is_deterministic_from_the_seed_and_seeds_draw_other_planes() -> None:
    one, two = FixateEnv(**SMALL), FixateEnv(**SMALL)
    first, info_first = one.reset(seed=3)
    again, info_again = two.reset(seed=3)
    for cam in ("cam1", "cam2"):
        np.testing.assert_array_equal(first[cam], again[cam])
    assert info_first["depth_m"] == info_again["depth_m"]
    assert info_first["texture_seed"] == info_again["texture_seed"]
    other, info_other = two.reset(seed=4)
    assert info_other["depth_m"] != info_first["depth_m"]
    assert 0.3 <= info_other["depth_m"] <= 2.0
    assert info_other["texture_seed"] != info_first["texture_seed"]
    assert np.mean(np.abs(other["cam1"].astype(float) - first["cam1"].astype(float))) > 5.0
    # The two envs share one OpenGL context: each draws its own texture all the same,
    # as a context made afresh for seed 4 does.
    still, *_ = one.step(np.zeros(3, np.float32))
    np.testing.assert_array_equal(still["cam1"], first["cam1"])
    release_renderers()
    fresh = FixateEnv(**SMALL)
    alone, _ = fresh.reset(seed=4)
    np.testing.assert_array_equal(alone["cam1"], other["cam1"])
    for env in (one, two, fresh):
        env.close()


def test_the_plane_stands_at_its_depth_and_the_vergence_error_is_the_geometrys() -> None:
    """Eyes parallel at rest: eye 1's axis meets the plane at its depth, and eye 2 misses
    that point by atan(baseline / depth)."""
    env = FixateEnv(**SMALL)
    for seed in (0, 5):
        _, info = env.reset(seed=seed)
        sim = env._sim
        assert sim is not None
        eye1 = sim.world_from_camera(1)[:3, 3]
        baseline = float(np.linalg.norm(sim.world_from_camera(2)[:3, 3] - eye1))
        depth = info["depth_m"]
        np.testing.assert_allclose(
            info["truth_world_m"], eye1 + np.array([0.0, depth, 0.0]), atol=1e-9
        )
        assert info["vergence_error_deg"] == pytest.approx(
            math.degrees(math.atan(baseline / depth)), abs=1e-9
        )
    env.close()


def test_vergence_error_falls_when_the_eyes_turn_in_and_grows_when_they_turn_out() -> None:
    env = FixateEnv(**SMALL)
    _, info = env.reset(seed=2)
    start = info["vergence_error_deg"]
    _, reward_in, _, _, info_in = env.step(CONVERGE)
    assert info_in["vergence_error_deg"] < start - 1.0
    env.reset(seed=2)
    _, reward_out, _, _, info_out = env.step(-CONVERGE)
    assert info_out["vergence_error_deg"] > start + 1.0
    assert -1.0 <= reward_out < reward_in <= 0.0
    # The reward: the error over the camera's half horizontal field of view.
    camera = env.base_settings.cameras[1]
    half_view_deg = math.degrees(math.atan(camera.width / 2 / camera.kx))
    assert reward_in == pytest.approx(-info_in["vergence_error_deg"] / half_view_deg)
    env.close()


def test_image_vergence_policy_brings_the_error_within_tolerance_on_pink_noise() -> None:
    env = FixateEnv(scene="textured_plane", max_steps=20)
    policy = VergencePolicy(env.action_space, env.period_s)
    tolerance_deg = math.degrees(math.atan(1.0 / env.base_settings.cameras[1].kx))
    for seed in range(3):
        obs, info = env.reset(seed=seed)
        policy.reset()
        start = info["vergence_error_deg"]
        for _ in range(20):
            obs, _, terminated, truncated, info = env.step(policy(obs))
            if terminated or truncated:
                break
        assert terminated, f"seed {seed}: error {info['vergence_error_deg']:.2f} deg"
        assert info["vergence_error_deg"] <= tolerance_deg < start
    env.close()


def test_vergence_policy_does_not_move_on_a_grating_it_cannot_match() -> None:
    """A grating of vertical stripes: its fovea has no vertical gradient (LOW_TEXTURE) and
    matches every period along the row; no action."""
    env = FixateEnv(scene="textured_plane", texture="grating")
    obs, _ = env.reset(seed=0)
    policy = VergencePolicy(env.action_space, env.period_s)
    assert policy.disparity_px(obs) is None
    np.testing.assert_array_equal(policy(obs), np.zeros(3, np.float32))
    env.close()


def test_texture_size_gives_a_texel_per_pixel() -> None:
    assert plane_texture_px(57.9) == 128
    assert plane_texture_px(115.9) == 256
    assert plane_texture_px(1e4) == 2048


def test_bad_options_name_the_field_and_what_is_allowed() -> None:
    with pytest.raises(SettingsError, match="scene must be one of marker, textured_plane"):
        FixateEnv(scene="room")
    with pytest.raises(SettingsError, match="texture must be one of pink, grating"):
        FixateEnv(scene="textured_plane", texture="stripes")
    with pytest.raises(SettingsError, match=r"reward for scene 'textured_plane'.*'offsets'"):
        FixateEnv(scene="textured_plane", reward="offsets")
    with pytest.raises(SettingsError, match=r"reward for scene 'marker'.*'vergence'"):
        FixateEnv(reward="vergence")
    with pytest.raises(SettingsError, match=r"plane_depth_m must lie within \[0.1, 5.0\]"):
        FixateEnv(scene="textured_plane", randomise={"plane_depth_m": (0.05, 1.0)})
    with pytest.raises(SettingsError, match="scene: the vectorised env has the marker scene only"):
        FixateVectorEnv(1, scene="textured_plane")


def test_position_reward_scores_the_heads_estimate_of_the_verged_point() -> None:
    """Verged by the image policy, the head's Model 1 estimate (encoders and belief) lies
    within a few percent of the plane point eye 1 looks at."""
    env = FixateEnv(scene="textured_plane", reward="position", max_steps=20)
    policy = VergencePolicy(env.action_space, env.period_s)
    obs, _ = env.reset(seed=1)
    reward = env.step(np.zeros(3, np.float32))[1]
    assert reward == -1.0  # eyes parallel: no estimate
    for _ in range(20):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        if terminated or truncated:
            break
    assert terminated
    assert -0.05 < reward <= 0.0
    assert info["estimate_world_m"] is not None
    env.close()


def test_vergence_policy_searches_inward_for_a_plane_nearer_than_its_row_reaches() -> None:
    """At 0.3 m camera 1's fovea lies about 58 px left of camera 2's centre, beyond the
    31 px template's reach in a 128 px row: LOST, so the policy turns the eyes in first."""
    env = FixateEnv(scene="textured_plane", randomise={"plane_depth_m": (0.3, 0.3)})
    policy = VergencePolicy(env.action_space, env.period_s)
    obs, info = env.reset(seed=0)
    policy.reset()
    assert policy.fovea_match(obs).status is MatchStatus.LOST
    assert policy(obs)[2] > 0.0
    for _ in range(10):
        obs, _, terminated, truncated, info = env.step(policy(obs))
        if terminated or truncated:
            break
    assert terminated, f"error {info['vergence_error_deg']:.2f} deg"
    env.close()


def test_set_texture_refuses_an_unknown_texture_or_another_size() -> None:
    env = FixateEnv(**SMALL)
    env.reset(seed=0)
    sim = env._sim
    assert sim is not None
    with pytest.raises(SettingsError, match="no texture 'nope' in this scene"):
        sim.set_texture("nope", np.zeros((8, 8, 3), np.uint8))
    with pytest.raises(SettingsError, match=r"texture 'gym_plane_texture' takes \(128, 128, 3\)"):
        sim.set_texture("gym_plane_texture", np.zeros((64, 64, 3), np.uint8))
    env.close()


def test_the_policies_never_import_the_scene_truth() -> None:
    """The vergence error is the env's teacher signal; a policy sees only observations."""
    source = Path(headsim.envs.policies.__file__).read_text(encoding="utf-8")
    modules = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.module:
            modules.add(node.module)
        elif isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names)
    assert "headsim.vision.correspondence" in modules  # the check sees its imports
    assert not modules & {"headsim.runs.landing", "headsim.scenario.surface_targets", "mujoco"}
