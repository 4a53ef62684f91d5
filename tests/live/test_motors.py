"""Motors (live/motors.py): speed and acceleration limits, saccade profiles."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.head.sim_head import SimHead
from headsim.live import LiveConfig, LiveHead, MotorLimits, Static
from headsim.live.motors import bang_bang_duration, min_jerk, min_jerk_duration
from headsim.sim.simulator import HeadSim

from .helpers import RED, small_head


def test_motors_keep_their_limits_and_images_see_the_eyes_where_they_are() -> None:
    limits = MotorLimits(max_speed=2.0, max_accel=40.0)
    config = LiveConfig(latency_frames=0, eye_limits=limits, neck_limits=limits)
    with HeadSim(settings=small_head()) as sim:
        live = LiveHead(SimHead(sim), config, "marker_red", Static((0.0, 0.7, 0.21)))
        live.now(lambda motors, now: motors.track(2, 0.3, 0.0, now))
        live.now(lambda motors, now: motors.track(0, -0.2, 0.0, now))
        speeds, refs, steps = [], [], []
        for _ in range(150):
            live.advance_to(live.time_s + live.dt)
            steps.append(live.step_count)
            speeds.append([m.vel for m in live.motors.motors])
            refs.append(live.motors.references)
            if live.step_count == 60:  # mid-move: the image shows the marker where the cameras are
                frame = live.capture()
                seen = RED(frame.images[0])
                assert seen.found
                np.testing.assert_allclose(
                    seen.uv, sim.project(frame.truth_target_world_m, 1)[0], atol=0.15
                )
                assert 0.02 < frame.truth_joints_rad[2] < 0.28
        speeds = np.array(speeds)
        assert np.abs(speeds).max() <= limits.max_speed + 1e-9
        consecutive = np.diff(steps) == 1  # the capture in between took several steps
        accel = np.abs(np.diff(speeds, axis=0))[consecutive]
        assert accel.max() <= limits.max_accel * live.dt + 1e-9
        np.testing.assert_allclose(refs[-1][[0, 2]], [-0.2, 0.3], atol=1e-6)
        np.testing.assert_allclose(live.true_joints()[[0, 2]], [-0.2, 0.3], atol=1e-3)


def test_saccade_profiles_fit_the_motor_limits_exactly() -> None:
    limits = MotorLimits(max_speed=5.0, max_accel=100.0)
    for amplitude in (0.05, 0.2, 0.5):
        duration = min_jerk_duration(amplitude, limits)
        times = np.linspace(0, duration, 2001)
        samples = np.array([min_jerk(0.0, amplitude, duration, t) for t in times])
        assert samples[-1, 0] == pytest.approx(amplitude)
        assert np.abs(samples[:, 1]).max() <= limits.max_speed * (1 + 1e-6)
        assert np.abs(samples[:, 2]).max() <= limits.max_accel * (1 + 1e-6)
        # One of the two limits is reached.
        assert (
            max(
                np.abs(samples[:, 1]).max() / limits.max_speed,
                np.abs(samples[:, 2]).max() / limits.max_accel,
            )
            > 0.999
        )
        bang = bang_bang_duration(amplitude, limits)
        assert bang < duration
    # Triangular and trapezoidal bang-bang moves, exactly.
    assert bang_bang_duration(0.1, limits) == pytest.approx(2 * np.sqrt(0.1 / 100))
    assert bang_bang_duration(1.0, limits) == pytest.approx(1.0 / 5 + 5 / 100)
