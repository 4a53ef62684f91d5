"""The live head: determinism, motion blur against a forward model, motor limits, pursuit."""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest

from headsim.live import (
    Jump,
    LiveConfig,
    LiveHead,
    MotorLimits,
    RandomWalk,
    Static,
    Visibility,
    Waypoints,
)
from headsim.live.gaze import GazeConfig, acquire, pursue
from headsim.live.motors import bang_bang_duration, min_jerk, min_jerk_duration
from headsim.sim.settings import IDEAL_FOCAL_PX, CameraSettings, HeadSettings, SettingsError
from headsim.sim.simulator import HeadSim
from headsim.vision.detect import colour_weight, find_marker

RED = partial(find_marker, colour="red")


def small_head(scale: float = 0.5) -> HeadSettings:
    focal = IDEAL_FOCAL_PX * scale
    cam = CameraSettings(width=int(640 * scale), height=int(480 * scale), kx=focal, ky=focal)
    return HeadSettings(cameras=(cam, cam))


def pursuit_run(seed: int, predictor: bool = True, duration_s: float = 0.6):
    with HeadSim(settings=small_head()) as sim:
        path = RandomWalk((0.0, 0.8, 0.3), max_speed_m_s=0.3, duration_s=2.0, seed=seed)
        live = LiveHead(sim, LiveConfig(latency_frames=1), "marker_red", path)
        estimator = acquire(live, RED)
        assert estimator is not None
        run = pursue(live, RED, estimator, duration_s, GazeConfig(predictor=predictor))
        return run, live.capture().images


def test_live_runs_are_identical_from_the_same_seed_and_differ_from_another() -> None:
    first, images_first = pursuit_run(seed=3)
    second, images_second = pursuit_run(seed=3)
    other, _ = pursuit_run(seed=4)
    assert len(first.records) == len(second.records) > 10
    for a, b in zip(first.records, second.records, strict=True):
        assert a.found and b.found
        np.testing.assert_array_equal(a.estimate_world_m, b.estimate_world_m)
        np.testing.assert_array_equal(a.encoders_rad, b.encoders_rad)
    for a, b in zip(images_first, images_second, strict=True):
        np.testing.assert_array_equal(a, b)
    truths = [r.truth_world_m for r in other.records]
    assert not np.allclose(truths[-1], first.records[-1].truth_world_m)


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
        live = LiveHead(sim, config, "marker_red", path)
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


def test_motors_keep_their_limits_and_images_see_the_eyes_where_they_are() -> None:
    limits = MotorLimits(max_speed=2.0, max_accel=40.0)
    config = LiveConfig(latency_frames=0, eye_limits=limits, neck_limits=limits)
    with HeadSim(settings=small_head()) as sim:
        live = LiveHead(sim, config, "marker_red", Static((0.0, 0.7, 0.21)))
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


def test_pursuit_predictor_cuts_the_lag_without_losing_the_target() -> None:
    with_predictor, _ = pursuit_run(seed=5, predictor=True, duration_s=1.0)
    without, _ = pursuit_run(seed=5, predictor=False, duration_s=1.0)
    assert with_predictor.losses == without.losses == 0
    assert with_predictor.frames_lost == 0
    assert with_predictor.lag_s() < without.lag_s()
    assert with_predictor.rms_offset_px() < without.rms_offset_px()


def test_live_settings_are_checked_with_the_field_named() -> None:
    with pytest.raises(SettingsError, match="exposure_s"):
        LiveConfig(frame_rate_hz=30, exposure_s=0.1)
    with pytest.raises(SettingsError, match="latency_frames"):
        LiveConfig(latency_frames=-1)
    with pytest.raises(SettingsError, match="max_accel"):
        MotorLimits(1.0, 0.0)
    with pytest.raises(SettingsError, match="speeds_m_s"):
        Waypoints(((0, 0, 0), (1, 0, 0)), (0.0,))


def test_pursuit_scenario_writes_results_and_a_recording_of_path_estimates_and_errors(
    tmp_path, capsys
) -> None:
    import json

    from rerun.chunk import RrdReader

    from headsim.cli import main

    rrd = tmp_path / "pursuit.rrd"
    code = main(
        ["run", "pursuit", "--fast", "--out", str(tmp_path), "--rrd", str(rrd), "--no-progress"]
    )
    out = capsys.readouterr().out
    assert code == 0, out
    experiment = json.loads((tmp_path / "results.json").read_text())["experiment"]
    frames = experiment["frames"]
    assert experiment["losses"] == 0 and frames == len(experiment["per_frame"]["error_m"])

    def frames_of(entity: str, component: str) -> list[object]:
        found = []
        for chunk in RrdReader(rrd).stream().filter(content=entity, components=component):
            batch = chunk.to_record_batch()
            names = batch.schema.names
            found += (
                batch.column("frame").to_pylist() if "frame" in names else [None] * batch.num_rows
            )
        return found

    assert frames_of("/world/pursuit/path", "LineStrips3D:strips") == [None]  # static
    errors = frames_of("/measurements/error_mm", "Scalars:scalars")
    assert len(errors) == frames and errors == sorted(
        errors
    )  # one per frame, on the frame timeline
    assert len(frames_of("/world/pursuit/estimates", "Points3D:positions")) == frames
    assert max(experiment["per_frame"]["error_m"]) < 0.02  # m, at about 1 m, 320 x 240


def test_losses_reacquisitions_and_a_target_that_disappears_and_reappears_elsewhere() -> None:
    centre, aside = (0.0, 0.8, 0.21), (0.08, 0.8, 0.24)
    out_of_view = (0.0, 0.8, 1.5)  # present, far above the view
    # Seen, then out of view for 0.1 s (a loss), then back (a re-acquisition).
    lost_path = Waypoints((centre, out_of_view, (0.0, 0.8, 1.501), centre), (1000.0, 0.01, 1000.0))
    # Seen, absent from 0.3 to 0.5 s, back elsewhere: no loss, a saccade, a new fixation.
    jump = Jump(centre, aside, 0.4)
    windows = Visibility(((0.0, 0.3), (0.5, 2.0)))
    runs = {}
    for name, path, visibility in (("lost", lost_path, None), ("jump", jump, windows)):
        with HeadSim(settings=small_head()) as sim:
            live = LiveHead(sim, LiveConfig(latency_frames=1), "marker_red", path, visibility)
            estimator = acquire(live, RED)
            assert estimator is not None
            runs[name] = pursue(live, RED, estimator, 1.0)
    lost, jumped = runs["lost"], runs["jump"]
    assert lost.losses == 1 and lost.reacquisitions == 1 and lost.frames_lost >= 3
    assert jumped.losses == 0 and jumped.frames_lost == 0
    assert sum(1 for r in jumped.records if r.truth_world_m is None) == 6  # 0.2 s at 30 Hz
    assert any(r.saccade for r in jumped.records if r.time_s >= 0.5)
    assert 0.0 < jumped.time_to_fixation_s(1.0, since_s=0.5) < 0.4


def test_acquiring_with_the_servos_windows_off_looks_at_whole_frames_only() -> None:
    from headsim.active.servo_types import ServoConfig
    from headsim.sim.events import ImageKind, ImageTaken

    class Sink:
        def __init__(self) -> None:
            self.kinds: list[ImageKind] = []

        def emit(self, event: object) -> None:
            if isinstance(event, ImageTaken):
                self.kinds.append(event.kind)

    kinds: dict[bool, list[ImageKind]] = {}
    for windows in (True, False):
        sink = Sink()
        with HeadSim(settings=small_head(), sink=sink) as sim:
            live = LiveHead(sim, LiveConfig(), "marker_red", Static((0.03, 0.8, 0.28)))
            estimator = acquire(live, RED, config=ServoConfig(windows=windows))
            assert estimator is not None
        kinds[windows] = sink.kinds
    assert set(kinds[False]) == {ImageKind.FULL}
    assert {ImageKind.PREVIEW, ImageKind.WINDOW} <= set(kinds[True])
