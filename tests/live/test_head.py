"""The live head (live/head.py): motion blur against a forward model, encoders, mid-exposure
images, latency, settings checks."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.head.sim_head import SimHead
from headsim.live import LiveConfig, LiveHead, MotorLimits, Static, Waypoints
from headsim.sim.settings import SettingsError
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import colour_weight

from .helpers import RED, small_head


def _weighted_u(image: np.ndarray) -> tuple[float, float]:
    weight = colour_weight(image, "red")
    weight = np.where(weight > 0.02, weight, 0.0)
    u = np.arange(image.shape[1])[None, :].repeat(image.shape[0], axis=0)
    mean = float((weight * u).sum() / weight.sum())
    return mean, float((weight * (u - mean) ** 2).sum() / weight.sum())


def test_motion_blur_centroid_and_streak_match_the_forward_model() -> None:
    """A marker crossing the view during the exposure: the blurred image's centroid is the
    mean of the marker's projections at the sub-frame instants, and its streak's variance
    along u is the still blob's plus the variance of those projections."""
    speed = 1.5  # m/s across the view at 0.6 m: ~24 px of travel in 1/60 s at f = 290 px
    path = Waypoints(((-0.1, 0.6, 0.21), (0.3, 0.6, 0.21)), (speed,))
    config = LiveConfig(frame_rate_hz=30.0, exposure_s=1 / 60, blur_subframes=9, latency_frames=0)
    with HeadSim(settings=small_head()) as sim:
        live = LiveHead(SimHead(sim), config, "marker_red", path)
        frame = live.capture()
        dt, n = live.dt, config.blur_subframes
        instants = [round((i + 0.5) * config.exposure_s / n / dt) * dt for i in range(n)]
        projected = np.array([sim.project(path.position(t), 1)[0] for t in instants])
        assert projected[-1, 0] - projected[0, 0] > 10  # a real streak, not a still blob
        # The colour weight is linear in the image, so the whole streak's weighted centroid
        # is the mean of the sub-frames' centroids (each within ~0.06 px of its projection).
        streak_mean, streak_var = _weighted_u(frame.images[0])
        assert abs(streak_mean - projected[:, 0].mean()) < 0.05
        # find_marker's thresholded centroid drops the streak's dim rim: a little looser.
        found = RED(frame.images[0])
        assert found.found
        np.testing.assert_allclose(found.uv, projected.mean(axis=0), atol=0.2)
        # The still blob at the mid instant, for its own spread.
        sim.set_body_pose("marker_red", path.position(instants[n // 2]))
        _, still_var = _weighted_u(sim.render(1))
        expected = still_var + projected[:, 0].var()
        assert streak_var == pytest.approx(expected, rel=0.1)


def test_an_image_is_taken_at_mid_exposure() -> None:
    """Without blur a frame is one render at the middle of its exposure: a moving marker is
    seen where it is then, half an exposure after the frame's start (8 px at 1.5 m/s here)."""
    exposure = 1 / 60
    path = Waypoints(((-0.1, 0.6, 0.21), (0.3, 0.6, 0.21)), (1.5,))
    config = LiveConfig(frame_rate_hz=30.0, exposure_s=exposure, latency_frames=0)
    with HeadSim(settings=small_head()) as sim:
        live = LiveHead(SimHead(sim), config, "marker_red", path)
        live.capture()
        frame = live.capture()
        start = config.period_s
        middle = round((start + exposure / 2) / live.dt) * live.dt
        assert frame.time_s == pytest.approx(middle, abs=1e-9)
        assert frame.end_s == pytest.approx(start + exposure, abs=live.dt)
        seen = RED(frame.images[0])
        assert seen.found
        at_middle = sim.project(path.position(middle), 1)[0]
        at_start = sim.project(path.position(start), 1)[0]
        np.testing.assert_allclose(seen.uv, at_middle, atol=0.15)
        assert at_middle[0] - at_start[0] > 5.0


def test_a_command_acts_the_latency_after_its_frame_ended() -> None:
    config = LiveConfig(frame_rate_hz=30.0, exposure_s=0.01, latency_frames=2)
    with HeadSim(settings=small_head()) as sim:
        live = LiveHead(SimHead(sim), config, "marker_red", Static((0.0, 0.6, 0.21)))
        frame = live.capture()
        acted: list[float] = []

        def turn_eyes(motors, now: float) -> None:  # type: ignore[no-untyped-def]
            acted.append(now)
            motors.track(2, 0.1, 0.0, now)

        live.send(turn_eyes, frame)
        due = frame.end_s + 2 / 30.0  # 10 ms of exposure, then two frame periods: 77 ms
        live.advance_to(due - 2 * live.dt)
        assert acted == [] and abs(live.true_joints()[2]) < 1e-9  # nothing yet
        live.advance_to(due + 0.05)
    assert len(acted) == 1 and acted[0] == pytest.approx(due, abs=live.dt)
    assert live.true_joints()[2] > 0.01  # and then the eyes turn


def test_live_settings_are_checked_with_the_field_named() -> None:
    with pytest.raises(SettingsError, match="exposure_s"):
        LiveConfig(frame_rate_hz=30, exposure_s=0.1)
    with pytest.raises(SettingsError, match="latency_frames"):
        LiveConfig(latency_frames=-1)
    with pytest.raises(SettingsError, match="max_accel"):
        MotorLimits(1.0, 0.0)
    with pytest.raises(SettingsError, match="speeds_m_s"):
        Waypoints(((0, 0, 0), (1, 0, 0)), (0.0,))


def test_encoders_follow_the_moving_joints_to_the_count_on_a_head_with_joint_errors() -> None:
    """With count errors and backlash (the realistic preset's) the encoders still read the
    joints the motors move, each within half a count, not the last at-rest command."""
    settings = replace(small_head(), count_error=True, backlash_rad=2.9e-4)
    resolution = settings.encoder_resolution_rad
    with HeadSim(settings=settings) as sim:
        live = LiveHead(
            SimHead(sim), LiveConfig(latency_frames=0), "marker_red", Static((0, 0.8, 0.2))
        )
        live.now(lambda motors, now: motors.set_velocity(0, 0.5))  # neck yaw at 0.5 rad/s
        frames = [live.capture() for _ in range(4)]
    for frame in frames:
        counts = frame.encoders_rad / resolution
        np.testing.assert_allclose(counts, np.round(counts), rtol=0, atol=1e-6)
        np.testing.assert_array_less(
            np.abs(frame.encoders_rad - frame.truth_joints_rad), 0.5 * resolution + 1e-12
        )
    yaw = [f.encoders_rad[0] for f in frames]
    assert np.all(np.diff(yaw) > 0.005)  # ~17 ms of 0.5 rad/s between frames at 30 Hz
