"""Lockstep heads against the classic live head (headsim.live.head.LiveHead on its own
HeadSim), with real renders: heads of different cameras, noise and baselines, still and
moving targets, commands at once and a frame late, give the classic path's images,
encoders and joints bit for bit."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.envs.fixate import TARGET_BODY, FixateEnv
from headsim.head.sim_head import SimHead
from headsim.live.head import LiveConfig, LiveHead
from headsim.live.paths import Static, Waypoints
from headsim.lockstep import LockstepHeads
from headsim.scenario.loading import load_scenario
from headsim.sim.settings import SettingsError
from headsim.sim.simulator import for_settings
from headsim.vision.markers import find_marker

STEPS = 5


def _heads() -> tuple[FixateEnv, list, list]:
    """Three heads of the Gym env's kind: another focal length, noise, another baseline;
    a still target, two moving ones."""
    env = FixateEnv()  # its base settings and model preparation (a 20 mm ball)
    base = env.base_settings
    one, two = base.cameras
    noisy = (replace(one, noise_std=2.0), replace(two, noise_std=2.0))
    longer = (replace(one, kx=one.kx * 1.1), replace(two, kx=two.kx * 1.1))
    settings = [
        base,
        replace(base, cameras=noisy, seed=7),
        replace(base, cameras=longer, baseline_m=0.16),
    ]
    paths = [
        Static((0.02, 0.9, 0.45)),
        Waypoints(((-0.05, 0.8, 0.4), (0.1, 0.8, 0.45)), (0.4,)),
        Waypoints(((0.05, 1.1, 0.5), (-0.1, 1.0, 0.4)), (0.3,)),
    ]
    return env, settings, paths


@pytest.mark.parametrize("latency_frames", [0, 1])
def test_lockstep_heads_see_and_move_as_classic_heads_do(latency_frames: int) -> None:
    env, settings, paths = _heads()
    config = LiveConfig(frame_rate_hz=30.0, latency_frames=latency_frames)
    heads = LockstepHeads(
        3, settings[0], config, target_body=TARGET_BODY, prepare=env.prepare_model
    )
    ids = np.arange(3)
    frames = [heads.reset(ids, settings, paths)]
    speeds = np.random.default_rng(0).uniform(-2.0, 2.0, (STEPS, 3, 3))
    for step in range(STEPS):
        heads.command_velocity(ids, speeds[step])
        frames.append(heads.capture(ids))
    heads.close()
    moved = 0.0
    for head in range(3):
        sim = for_settings(settings[head])
        env.prepare_model(sim.model)
        live = LiveHead(SimHead(sim), config, target_body=TARGET_BODY, path=paths[head])
        classic = [live.capture()]
        for step in range(STEPS):

            def command(motors, _now, s=speeds[step, head]) -> None:
                for motor, speed in enumerate(s):
                    motors.set_velocity(motor, float(speed))

            if latency_frames:
                live.send(command, classic[-1])
            else:
                live.now(command)
            classic.append(live.capture())
        sim.close()
        for ours, theirs in zip(frames, classic, strict=True):
            assert ours.time_s[head] == theirs.time_s
            np.testing.assert_array_equal(ours.images[head, 0], theirs.images[0])
            np.testing.assert_array_equal(ours.images[head, 1], theirs.images[1])
            np.testing.assert_array_equal(ours.encoders_rad[head], theirs.encoders_rad)
            np.testing.assert_array_equal(ours.truth_joints_rad[head], theirs.truth_joints_rad)
            np.testing.assert_array_equal(
                ours.truth_target_world_m[head], theirs.truth_target_world_m
            )
        moved = max(moved, float(np.abs(classic[-1].truth_joints_rad).max()))
    assert moved > 0.05  # the heads did move: the comparison is not of heads at rest


def test_bad_arguments_name_what_is_allowed() -> None:
    env = FixateEnv()
    with pytest.raises(SettingsError, match="n must be a whole number >= 1, got 0"):
        LockstepHeads(0, env.base_settings)
    with pytest.raises(SettingsError, match=r"supersample must be None or 1\.\.8, got 9"):
        LockstepHeads(1, env.base_settings, supersample=9)
    with pytest.raises(SettingsError, match="exposure_s: lockstep heads take instantaneous"):
        LockstepHeads(1, env.base_settings, LiveConfig(exposure_s=0.01))
    with pytest.raises(SettingsError, match="'nothing' is not a movable"):
        LockstepHeads(1, env.base_settings, target_body="nothing")


def test_the_quick_starts_heads_at_its_targets_see_what_the_classic_heads_see() -> None:
    """The quick start's realistic head (distorted lenses, noise, mounts and tolerances, its
    own seed) before each of its targets, turning: the classic live head's images and
    encoders, bit for bit."""
    scenario = load_scenario("quickstart", fast=True)
    settings = scenario.settings
    targets = [Static(t.position_world_m) for t in scenario.scene.targets]
    n = len(targets)
    config = LiveConfig(latency_frames=0)
    heads = LockstepHeads(n, settings, config, target_body="marker_red")
    ids = np.arange(n)
    frames = [heads.reset(ids, [settings] * n, targets)]
    speeds = np.array([[0.2, -0.1, 0.4], [-0.3, 0.1, -0.2], [0.1, 0.2, 0.3]])[:n]
    heads.command_velocity(ids, speeds)
    frames.append(heads.capture(ids))
    heads.close()
    assert frames[0].images.shape[2:] == (480, 640, 3)
    seen = [find_marker(frames[-1].images[h, c], "red").area_px for h in ids for c in (0, 1)]
    assert min(seen) > 0  # every eye sees its head's target: the images are not empty views
    for head in range(n):
        with for_settings(settings) as sim:
            live = LiveHead(SimHead(sim), config, target_body="marker_red", path=targets[head])
            classic = [live.capture()]

            def command(motors, _now, s=speeds[head]) -> None:
                for motor, speed in enumerate(s):
                    motors.set_velocity(motor, float(speed))

            live.now(command)
            classic.append(live.capture())
        for ours, theirs in zip(frames, classic, strict=True):
            np.testing.assert_array_equal(ours.images[head, 0], theirs.images[0])
            np.testing.assert_array_equal(ours.images[head, 1], theirs.images[1])
            np.testing.assert_array_equal(ours.encoders_rad[head], theirs.encoders_rad)
