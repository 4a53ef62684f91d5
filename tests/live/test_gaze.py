"""Gaze (live/gaze.py): determinism, acquisition, pursuit, losses and re-acquisitions."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.active.measurement import HeadKnowledge
from headsim.active.neck_servo import NeckServo
from headsim.estimators import model2
from headsim.geometry.kinematics import head_to_world
from headsim.head.sim_head import SimHead
from headsim.live import Jump, LiveConfig, LiveHead, RandomWalk, Static, Visibility, Waypoints
from headsim.live.estimator import GazeEstimator
from headsim.live.gaze import GazeConfig, acquire, pursue
from headsim.sim.settings import HeadBelief
from headsim.sim.simulator import HeadSim

from .helpers import RED, small_head


def pursuit_run(seed: int, predictor: bool = True, duration_s: float = 0.6):
    with HeadSim(settings=small_head()) as sim:
        path = RandomWalk((0.0, 0.8, 0.3), max_speed_m_s=0.3, duration_s=2.0, seed=seed)
        live = LiveHead(SimHead(sim), LiveConfig(latency_frames=1), "marker_red", path)
        estimator = acquire(live, NeckServo(live.head), RED)
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


def test_pursuit_predictor_cuts_the_lag_without_losing_the_target() -> None:
    with_predictor, _ = pursuit_run(seed=5, predictor=True, duration_s=1.0)
    without, _ = pursuit_run(seed=5, predictor=False, duration_s=1.0)
    assert with_predictor.losses == without.losses == 0
    assert with_predictor.frames_lost == 0
    assert with_predictor.lag_s() < without.lag_s()
    assert with_predictor.rms_offset_px() < without.rms_offset_px()


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
            live = LiveHead(
                SimHead(sim), LiveConfig(latency_frames=1), "marker_red", path, visibility
            )
            estimator = acquire(live, NeckServo(live.head), RED)
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
            live = LiveHead(SimHead(sim), LiveConfig(), "marker_red", Static((0.03, 0.8, 0.28)))
            estimator = acquire(live, NeckServo(live.head, ServoConfig(windows=windows)), RED)
            assert estimator is not None
        kinds[windows] = sink.kinds
    assert set(kinds[False]) == {ImageKind.FULL}
    assert {ImageKind.PREVIEW, ImageKind.WINDOW} <= set(kinds[True])


def test_the_live_estimate_measures_with_the_heads_belief_not_its_true_geometry() -> None:
    """Same true head, same images: the estimate moves exactly as the believed geometry does."""
    truth = replace(small_head(), baseline_m=0.153, neck_d1_m=0.125, neck_a2_m=0.088)
    design = HeadBelief()  # 150 mm, 0.12 m, 0.09 m: the head's own drawings, not its truth
    wider = HeadBelief(baseline_m=1.1 * design.baseline_m, neck_d1_m=0.13, neck_a2_m=0.1)
    measured = {}
    for name, settings, knowledge in (
        ("design", replace(truth, belief=design), None),  # the simulator's belief
        ("wider", truth, HeadKnowledge(belief=wider)),  # the knowledge's own belief
    ):
        with HeadSim(settings=settings) as sim:
            live = LiveHead(SimHead(sim), LiveConfig(), "marker_red", Static((0.03, 0.8, 0.24)))
            estimator = acquire(live, NeckServo(live.head), RED, knowledge)
            assert estimator is not None
            frame = live.capture()
            uv = tuple(RED(image).uv for image in frame.images)
            measured[name] = (estimator.measure(uv, frame.encoders_rad), frame.encoders_rad)
    (a, enc_a), (b, enc_b) = measured["design"], measured["wider"]
    np.testing.assert_array_equal(enc_a, enc_b)  # the true head moved the same way
    np.testing.assert_array_equal(a.error_px, b.error_px)  # and saw the same images
    # Depth scales with the believed baseline (no line-of-sight offsets believed).
    assert b.estimate_head_m[2] / a.estimate_head_m[2] == pytest.approx(1.1, rel=1e-12)
    # To W through eq. (3) with the believed D-H lengths (the true ones put it elsewhere).
    for offsets, belief in ((a, design), (b, wider)):
        head, yaw, pitch = offsets.estimate_head_m, enc_a[0], enc_a[1]
        believed = head_to_world(head, yaw, pitch, belief.neck_d1_m, belief.neck_a2_m)
        true = head_to_world(head, yaw, pitch, truth.neck_d1_m, truth.neck_a2_m)
        np.testing.assert_allclose(offsets.estimate_world_m, believed, rtol=0, atol=1e-12)
        assert np.linalg.norm(believed - true) > 1e-3


def test_the_live_lines_of_sight_cross_where_model_2s_do_offsets_included() -> None:
    """The believed line-of-sight offsets act on depth and x as in the at-rest Model 2."""
    resolution = 2 * np.pi / 25600
    jacobian = np.array([[-2.0, 0.3, 2.5], [-2.0, -0.2, -2.4], [0.1, 2.2, 0.05]])  # px/step
    goals = ((160.0, 120.0), (161.0, 119.0))
    offsets_m = (0.001, -0.0005)
    belief = HeadBelief(baseline_m=0.1503)
    knowledge = HeadKnowledge(alpha_e=(0.01, -0.02), los_offset_m=offsets_m)
    live = GazeEstimator(jacobian, resolution, goals, belief, knowledge, offsets_m)
    encoders = np.array([0.05, -0.1, 0.09])
    uv = ((171.0, 125.0), (150.0, 128.0))
    gains = jacobian[:2, 2] / resolution
    alpha = [encoders[2] - (uv[i][0] - goals[i][0]) / gains[i] for i in range(2)]
    rest = model2(
        [alpha[0]],
        [alpha[1]],
        [uv[0]],
        [uv[1]],
        belief.baseline_m,
        uv10=goals[0],
        uv20=goals[1],
        alpha_e=knowledge.alpha_e,
        los_offset_m=offsets_m,
    )
    estimate = live.measure(uv, encoders).estimate_head_m
    np.testing.assert_allclose(estimate[[0, 2]], rest.positions[0][[0, 2]], rtol=1e-12)


def test_acquire_refuses_a_servo_on_another_head() -> None:
    with HeadSim(settings=small_head()) as sim, HeadSim(settings=small_head()) as other:
        live = LiveHead(SimHead(sim), LiveConfig(), "marker_red", Static((0.03, 0.8, 0.28)))
        with pytest.raises(ValueError, match=r"servo must drive the live head's head"):
            acquire(live, NeckServo(SimHead(other)), RED)
