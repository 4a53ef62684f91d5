"""What procedures and servos report to an event sink, on real renders: every fixation,
image, detection, move and result, and nothing that changes a measurement."""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from headsim.active.calibration import calibrate_head
from headsim.active.events import (
    CalibrationPosition,
    Detected,
    FixationStarted,
    MeasurementDone,
    ServoKind,
    ServoStep,
)
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import body_target
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.head.sim_head import SimHead
from headsim.procedures.chessboard import measure_chessboard
from headsim.procedures.tracking import track_moving_target
from headsim.sim import names
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))
BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))


class ListSink:
    def __init__(self) -> None:
        self.events: list[object] = []

    def emit(self, event: object) -> None:
        self.events.append(event)

    def of(self, kind: type) -> list:  # type: ignore[type-arg]
        return [e for e in self.events if isinstance(e, kind)]


def _at(sim: HeadSim, body: str, p_head: list[float]) -> np.ndarray:
    p_world = sim.transform_points(np.asarray(p_head, float), "head", "world")[0]
    sim.set_body_pose(body, p_world)
    return p_world


def test_a_sink_sees_every_image_and_detection_and_changes_no_measurement() -> None:
    measured = []
    for sink in (None, ListSink()):
        with HeadSim("default", sink=sink) as sim:
            servo = EyeServo(sim)
            _at(sim, "marker_red", [0.05, -0.03, 0.6])
            first = measure_model2(sim, servo, RED)
            _at(sim, "marker_red", [-0.04, 0.02, 0.7])  # windows and previews from here on
            second = measure_model2(sim, servo, RED)
            measured.append((first, second, sim.render_count, servo.looker.counts.window_misses))
    assert sink is not None
    (a1, a2, renders, misses), (b1, b2, renders_b, misses_b) = measured
    for a, b in ((a1, b1), (a2, b2)):
        assert a.ok and b.ok
        np.testing.assert_array_equal(a.estimate_head_m, b.estimate_head_m)
        assert a.renders == b.renders
    assert renders == renders_b and misses == misses_b
    images = sink.of(ImageTaken)
    assert len(images) == renders
    kinds = {e.kind for e in images}
    # No full frame: a new target's first look is a preview's window, the probe's a band.
    assert {ImageKind.WINDOW, ImageKind.PREVIEW} <= kinds and ImageKind.FULL not in kinds
    assert sum(e.kind is ImageKind.RETAKE for e in images) == misses
    # A detection follows each image the servo looked in (previews only place windows).
    looked = [e for e in images if e.kind is not ImageKind.PREVIEW]
    detections = sink.of(Detected)
    assert len(detections) == len(looked)
    order = [e for e in sink.events if isinstance(e, ImageTaken | Detected)]
    for before, after in pairwise(order):
        if isinstance(after, Detected):
            assert isinstance(before, ImageTaken) and before.camera == after.camera
    # In full-frame pixels, also where the detector saw only a window.
    windowed = [
        d for i, d in pairwise(order) if isinstance(d, Detected) and i.kind is ImageKind.WINDOW
    ]
    assert any(d.status is DetectionStatus.FOUND for d in windowed)
    found = [d.uv_px for d in windowed if d.uv_px is not None]
    assert all(20 < u < 620 and 20 < v < 460 for u, v in found)
    # Each eye-servo move is reported, numbered, with the residual it left.
    steps = sink.of(ServoStep)
    assert steps and all(s.servo is ServoKind.EYE and len(s.steps) == 1 for s in steps)


def test_each_servo_move_is_reported_with_where_it_went_and_what_it_left() -> None:
    sink = ListSink()
    with HeadSim("default", sink=sink) as sim:
        _at(sim, "marker_red", [0.08, 0.0, 0.6])
        result = EyeServo(sim).run(1, RED.detector)
        goal_u = sim.camera_settings(1).image_centre[0]
    assert result.converged
    moves = sink.of(ServoStep)
    assert [m.iteration for m in moves] == list(range(1, len(moves) + 1))
    assert len(moves) >= 2  # a probe, then moves with the learnt gain
    visited = [(s, u) for s, u, _ in result.seen]
    assert [(m.steps[0], m.residual_px[0]) for m in moves if m.residual_px is not None] == [
        (s, u - goal_u) for s, u in visited[1:]
    ]


def test_procedures_report_each_fixation_with_its_label_and_result() -> None:
    sink = ListSink()
    with HeadSim("chessboard", sink=sink) as sim:
        sim.set_body_pose(names.CHESSBOARD, [-0.105, 0.8, 0.285])
        head = SimHead(sim)
        run = measure_chessboard(head, EyeServo(head), corners=[9, 10])
    labels = [e.label for e in sink.of(FixationStarted)]
    assert labels == ["corner_1_1", "corner_2_1"]
    done = sink.of(MeasurementDone)
    assert [d.measurement for d in done] == list(run.measurements)
    # Each corner's images come after its fixation starts and before its result.
    first_image = next(i for i, e in enumerate(sink.events) if isinstance(e, ImageTaken))
    assert isinstance(sink.events[first_image - 1], FixationStarted)


def test_calibration_reports_each_position_and_tracking_each_time() -> None:
    sink = ListSink()
    with HeadSim("default", sink=sink) as sim:
        positions = np.array(
            [
                sim.transform_points(np.array(p, float), "head", "world")[0]
                for p in ([0.03, -0.02, 0.35], [-0.05, 0.02, 0.45], [0.06, 0.03, 0.55])
            ]
        )
        run = calibrate_head(sim, EyeServo(sim), BALL, names.CALIBRATION_BALL, positions)
    assert [e.label for e in sink.of(FixationStarted)] == [
        "calibration 1",
        "calibration 2",
        "calibration 3",
    ]
    reported = sink.of(CalibrationPosition)
    assert [p.index for p in reported] == [0, 1, 2]
    np.testing.assert_array_equal(np.array([p.position_world_m for p in reported]), positions)
    assert tuple(p.measurement.failure for p in reported) == run.outcomes

    sink = ListSink()
    with HeadSim("default", sink=sink) as sim:

        def path(t: float) -> np.ndarray:
            return np.array([0.05 * t, 0.7, 0.25])

        head = SimHead(sim)
        tracked = track_moving_target(head, NeckServo(head), RED, "marker_red", path, [0.0, 0.5])
    assert [e.label for e in sink.of(FixationStarted)] == ["marker_red 1", "marker_red 2"]
    done = sink.of(MeasurementDone)
    assert [d.time_s for d in done] == [0.0, 0.5]
    assert [d.measurement for d in done] == list(tracked.measurements)
    moves = sink.of(ServoStep)
    assert moves and all(s.servo is ServoKind.NECK and len(s.steps) == 3 for s in moves)
