"""Running a scenario: calibrate if asked, run the procedure, collect the results.

The procedures of :mod:`headsim.active.procedures` run unchanged.  What a run shows
while it goes (progress, the Rerun recording) hooks in from outside them:

- :class:`ObservedSim` is a :class:`HeadSim` that reports every image it
  renders and every body it moves;
- :class:`ObservedEyeServo` and :class:`ObservedNeckServo` wrap the detector
  they are given, so every detection is reported with the image it was made in.

Both report to a :class:`Hub`, which numbers images (``frame``) and
fixations (``step``) over the whole run and passes them on to
:class:`Observer` objects.  Nothing is rendered for the observers: they see
the experiment's own images.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, fields, replace
from functools import partial
from typing import Any, TextIO

import numpy as np

from headsim.active.procedures import (
    CalibrationError,
    CalibrationRun,
    HeadKnowledge,
    Measurement,
    Model2Config,
    Target,
    calibrate_head,
    calibration_layout,
    line_of_sight_truth,
    measure_chessboard,
    measure_model1,
    measure_model2,
    relative_positioning,
    track_moving_target,
)
from headsim.active.search import Failure
from headsim.active.servo import Detector, EyeServo, NeckServo, NeckServoResult, ServoConfig
from headsim.estimators.result import Status
from headsim.run.outcomes import (
    CalibrationLayout,
    CalibrationReport,
    CalibrationSource,
    CheckTarget,
    ChessboardPaper,
    ChessboardResult,
    Experiment,
    KnowledgeReport,
    LinesOfSightFit,
    MeasurementRecord,
    PointsResult,
    PositionOutcome,
    PursuitFigures,
    PursuitResult,
    RelativeObject,
    RelativePaper,
    RelativeResult,
    RunResult,
    TrackingResult,
    VerticalReference,
)
from headsim.run.serialise import calibration_from_block
from headsim.scenario.calibration_design import near_far_depths, near_fraction
from headsim.scenario.schema import (
    CHESSBOARD_PATTERN,
    CHESSBOARD_SQUARE_M,
    MARKER_BODIES,
    STREAM_CALIBRATION,
    STREAM_DEPTH_NOISE,
    Scenario,
)
from headsim.sim import names
from headsim.sim.render import Window
from headsim.sim.settings import PAPER_INITIAL_DIRECTIONS
from headsim.sim.simulator import CameraId, HeadSim
from headsim.vision.detect import find_cross_point, find_marker

#: Where unused bodies are parked: under the table, out of every camera's view (W, m).
PARKED_WORLD_M = (0.0, 0.5, -1.0)
#: What the paper reports for each experiment (Sec. VI).
PAPER: dict[str, Any] = {
    "alpha_e_rad": PAPER_INITIAL_DIRECTIONS,
    "chessboard_side_mean_m": 0.0303,
    "chessboard_side_std_m": 0.000677,
    "relative_alpha1_rad": 0.08,
    "relative_alpha2_rad": 0.0349,
    "relative_objects": 6,
}


class Observer:
    """What a run reports as it goes; every method is a no-op here.

    ``frame`` numbers the images rendered over the whole run, from 0; ``step``
    numbers the fixations (calibration samples first, then measurements), from 0.
    """

    def phase(
        self, name: str, sim: HeadSim, knowledge: HeadKnowledge, truth: dict[str, np.ndarray]
    ) -> None:
        """A phase ("calibration", "measurement") starts in ``sim``; ``truth``: label -> W, m."""

    def step(self, step: int, label: str) -> None:
        """Fixation ``step`` begins (target ``label``)."""

    def rendered(self, sim: HeadSim, camera: int, image: np.ndarray, frame: int) -> None:
        """Camera 1 or 2 rendered ``image`` (the experiment's own image)."""

    def detected(
        self, sim: HeadSim, camera: int, uv: tuple[float, float] | None, status: str, frame: int
    ) -> None:
        """The target was looked for in ``frame`` (camera ``camera``): where, or why not."""

    def measured(self, record: MeasurementRecord) -> None:
        """A measurement is finished."""

    def calibrated(self, calibration: CalibrationReport) -> None:
        """The calibration is finished."""

    def pursued(self, record: Any, frame: int) -> None:
        """A live frame of the pursuit procedure (``headsim.live.gaze.FrameRecord``) is measured."""

    def finished(self, result: RunResult) -> None:
        """The run is over."""


class Hub:
    """Numbers frames and steps and passes every event on to the observers."""

    def __init__(self, observers: Sequence[Observer] = ()) -> None:
        self.observers = list(observers)
        self.frame = 0
        self.step = -1
        self.steps: list[int] = []  # steps begun in the current phase, in order
        self.camera = 0
        self.offset_px = (0, 0)
        self.rendered_frames = 0.0
        self.windows = 0
        self.window_misses = 0
        self.previews = 0
        self._watched: tuple[str, str] | None = None
        self._detector: Detector | None = None
        self._auto_label: Callable[[], str] | None = None

    def phase(
        self, name: str, sim: HeadSim, knowledge: HeadKnowledge, truth: dict[str, np.ndarray]
    ) -> None:
        self.steps = []
        self._watched, self._detector, self._auto_label = None, None, None
        for o in self.observers:
            o.phase(name, sim, knowledge, truth)

    def begin(self, label: str) -> int:
        """A new fixation begins; returns its step."""
        self.step += 1
        self.steps.append(self.step)
        for o in self.observers:
            o.step(self.step, label)
        return self.step

    def watch(self, body: str, label: str) -> None:
        """Begin a step each time ``body`` is moved (a procedure placing its target)."""
        self._watched = (body, label)

    def step_per_target(self, label: Callable[[], str]) -> None:
        """Begin a step each time the servo is handed a new target's detector."""
        self._auto_label = label

    def placed(self, body: str) -> None:
        if self._watched is not None and body == self._watched[0]:
            self.begin(f"{self._watched[1]} {len(self.steps) + 1}")

    def rendered(
        self,
        sim: HeadSim,
        camera: int,
        image: np.ndarray,
        offset_px: tuple[int, int] = (0, 0),
    ) -> None:
        """An image was rendered; ``offset_px``: where the detector's image (a window) starts."""
        self.camera = camera
        self.offset_px = offset_px
        for o in self.observers:
            o.rendered(sim, camera, image, self.frame)
        self.frame += 1

    def detector(self, sim: HeadSim, detector: Detector) -> Detector:
        """``detector``, reporting each detection (made in the image rendered last)."""
        if self._auto_label is not None and detector is not self._detector:
            self._detector = detector
            self.begin(self._auto_label())

        def observed(image: np.ndarray) -> Any:
            detection = detector(image)
            uv = detection.uv if detection.found else None
            if uv is not None:  # in the full frame's pixels
                uv = (uv[0] + self.offset_px[0], uv[1] + self.offset_px[1])
            for o in self.observers:
                o.detected(sim, self.camera, uv, detection.status.value, self.frame - 1)
            return detection

        return observed

    def measured(self, record: MeasurementRecord) -> None:
        for o in self.observers:
            o.measured(record)

    def calibrated(self, calibration: CalibrationReport) -> None:
        for o in self.observers:
            o.calibrated(calibration)

    def pursued(self, record: Any) -> None:
        for o in self.observers:
            o.pursued(record, self.frame - 1)

    def finished(self, result: RunResult) -> None:
        for o in self.observers:
            o.finished(result)


class ObservedSim(HeadSim):
    """A :class:`HeadSim` that reports its renders and body moves to a :class:`Hub`."""

    def __init__(self, hub: Hub, scene: str, scenario: Scenario) -> None:
        super().__init__(scene, scenario.settings, settle_mode=scenario.settle_mode)
        self.hub = hub
        #: Each camera's last whole image, the backdrop of the windows that follow it.
        self._last_full: dict[int, np.ndarray] = {}

    def render(self, camera: CameraId) -> np.ndarray:
        before = self.rendered_frames
        image = super().render(camera)
        self.hub.rendered_frames += self.rendered_frames - before
        self._last_full[self.camera_index(camera)] = image
        self.hub.rendered(self, self.camera_index(camera) + 1, image)
        return image

    def retake(self, camera: CameraId) -> np.ndarray:
        before = self.rendered_frames
        image = super().retake(camera)
        self.hub.rendered_frames += self.rendered_frames - before
        self._last_full[self.camera_index(camera)] = image
        self.hub.rendered(self, self.camera_index(camera) + 1, image)
        return image

    def render_preview(self, camera: CameraId, binning: int) -> np.ndarray:
        """A binned preview: counted (pixels, previews), not shown to observers."""
        before = self.rendered_frames
        image = super().render_preview(camera, binning)
        self.hub.rendered_frames += self.rendered_frames - before
        self.hub.previews += 1
        return image

    def render_window(self, camera: CameraId, window: Window) -> np.ndarray:
        """The window; observers see it in a full-size frame: around it the camera's last
        whole image at half brightness (not rendered now), or black before there is one."""
        before = self.rendered_frames
        image = super().render_window(camera, window)
        self.hub.rendered_frames += self.rendered_frames - before
        self.hub.windows += 1
        if not self.hub.observers:  # nobody looks at the frame: only count the render
            self.hub.rendered(self, self.camera_index(camera) + 1, image, (window.x0, window.y0))
            return image
        settings = self.camera_settings(camera)
        last = self._last_full.get(self.camera_index(camera))
        if last is not None and last.shape == (settings.height, settings.width, 3):
            frame = last // 2
        else:
            frame = np.zeros((settings.height, settings.width, 3), dtype=np.uint8)
        frame[window.y0 : window.y1, window.x0 : window.x1] = image
        self.hub.rendered(self, self.camera_index(camera) + 1, frame, (window.x0, window.y0))
        return image

    def set_body_pose(
        self, name: str, position_world_m: np.ndarray, quat_world: np.ndarray | None = None
    ) -> None:
        super().set_body_pose(name, position_world_m, quat_world)
        self.hub.placed(name)


class ObservedEyeServo(EyeServo):
    """An :class:`EyeServo` whose detections are reported to the sim's hub.

    Every image the eye servo looks at goes through :meth:`EyeServo.observe`
    (also inside :meth:`EyeServo.run`), so wrapping it there catches them all.
    """

    sim: ObservedSim

    def observe(self, camera: int, detector: Detector, key: object = None) -> Any:
        key = detector if key is None else key
        misses = self.window_misses
        detection = super().observe(camera, self.sim.hub.detector(self.sim, detector), key)
        self.sim.hub.window_misses += self.window_misses - misses
        return detection


class ObservedNeckServo(NeckServo):
    """A :class:`NeckServo` whose detections are reported to the sim's hub."""

    sim: ObservedSim

    def run(
        self,
        detector: Detector,
        goals: tuple[float, float, float] | None = None,
        key: object = None,
    ) -> NeckServoResult:
        key = detector if key is None else key
        misses = self.window_misses
        result = super().run(self.sim.hub.detector(self.sim, detector), goals, key)
        self.sim.hub.window_misses += self.window_misses - misses
        return result

    def look_from(self, steps: tuple[int, int, int], detector: Detector) -> bool:
        return super().look_from(steps, self.sim.hub.detector(self.sim, detector))


class Progress(Observer):
    """A one-line text progress bar: fixations done of ``total``, rate, time left.

    Drawn on ``stream`` (stderr by the CLI, which keeps stdout for the
    summary) at most every ``interval_s``, and once more at the end.
    """

    def __init__(
        self,
        total: int,
        stream: TextIO,
        *,
        width: int = 24,
        interval_s: float = 0.25,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.total = max(int(total), 1)
        self.stream = stream
        self.width = width
        self.interval_s = interval_s
        self.clock = clock
        self.start = clock()
        self.done = 0
        self.label = ""
        self._drawn_at = -math.inf
        self._length = 0

    def line(self) -> str:
        """The bar as it stands, e.g. ``[######------] 12/48 fixations  3.1/s  0:11 left  corner_3_1``."""
        done = min(self.done, self.total)
        filled = round(self.width * done / self.total)
        elapsed = max(self.clock() - self.start, 1e-9)
        rate = done / elapsed
        if done >= self.total:
            left = f"{elapsed:.1f} s"
        elif rate > 0:
            seconds = round((self.total - done) / rate)
            left = f"{seconds // 60}:{seconds % 60:02d} left"
        else:
            left = "-:-- left"
        bar = "#" * filled + "-" * (self.width - filled)
        return f"[{bar}] {done}/{self.total} fixations  {rate:.1f}/s  {left}  {self.label}".rstrip()

    def _draw(self, force: bool = False) -> None:
        now = self.clock()
        if not force and now - self._drawn_at < self.interval_s:
            return
        self._drawn_at = now
        text = self.line()
        self.stream.write("\r" + text.ljust(self._length))
        self.stream.flush()
        self._length = len(text)

    def step(self, step: int, label: str) -> None:
        self.done, self.label = step, label
        self._draw()

    def finished(self, result: RunResult) -> None:
        self.done, self.label = self.total, ""
        self._draw(force=True)
        self.stream.write("\n")
        self.stream.flush()


# -- phases ----------------------------------------------------------------------


def _servo_config(scenario: Scenario) -> ServoConfig:
    return ServoConfig(**asdict(scenario.experiment.servo))


def _model2_config(scenario: Scenario) -> Model2Config:
    e = scenario.experiment
    return Model2Config(interpolate=e.interpolate, midline_px=e.midline_px, remedy_px=e.remedy_px)


def marker_target(name: str, body: str) -> Target:
    """A marker body of the default scene, found by its colour, named ``name``."""
    return Target(
        name, partial(find_marker, colour=MARKER_BODIES[body]), lambda sim: sim.position(body)
    )


def _told(scenario: Scenario) -> HeadKnowledge:
    """What the scenario tells the head before any calibration: its goal columns, if given."""
    goals = scenario.experiment.goal_columns_px
    return HeadKnowledge() if goals is None else HeadKnowledge(u0=goals)


def _calibrate(scenario: Scenario, hub: Hub) -> tuple[CalibrationRun | None, CalibrationReport]:
    """Sec. V in the default scene; returns the run (None if it failed) and its report."""
    spec = scenario.experiment.calibration
    assert spec is not None
    seed = scenario.seed
    with ObservedSim(hub, "default", scenario) as sim:
        try:
            positions = calibration_layout(
                sim,
                np.random.default_rng([seed, STREAM_CALIBRATION]),
                spec.targets,
                spec.depth_m,
                spec.lateral,
                spec.vertical,
                depths_m=near_far_depths(spec.targets, spec.depth_m, spec.near_fraction)
                if spec.layout == "near_far"
                else None,
            )
        except ValueError as err:
            report = CalibrationReport(
                status=Status.FAILED,
                detail=f"failed: {err}",
                targets=spec.targets,
                fixated=0,
                renders=0,
                positions=(),
            )
            hub.calibrated(report)
            return None, report
        truth = {f"calibration {k + 1}": p for k, p in enumerate(positions)}
        hub.phase("calibration", sim, HeadKnowledge(), truth)
        hub.watch(names.CALIBRATION_BALL, "calibration")
        ball = marker_target(names.CALIBRATION_BALL, names.CALIBRATION_BALL)
        truth_alpha_e = [sim.effective_initial_direction(c) for c in (1, 2)]
        truth_v0 = [sim.camera_settings(c).principal[1] for c in (1, 2)]
        truth_ratio = [sim.camera_settings(c).kx / sim.camera_settings(c).ky for c in (1, 2)]
        planned = CalibrationReport(
            status=Status.OK,
            detail="",
            targets=spec.targets,
            fixated=0,
            renders=0,
            positions=(),
            layout=CalibrationLayout(
                kind=spec.layout,
                near_fraction=(
                    (spec.near_fraction or near_fraction(spec.depth_m))
                    if spec.layout == "near_far"
                    else None
                ),
                depth_m=list(spec.depth_m),
                lateral=spec.lateral,
                vertical=spec.vertical,
                positions_world_m=positions,
            ),
            depth_noise_m=spec.depth_noise_m,
            position_noise_m=spec.position_noise_m,
            lines_of_sight_fit=spec.lines_of_sight,
            extended=spec.extended,
            alpha_e_truth_rad=truth_alpha_e,
            alpha_e_paper_rad=list(PAPER["alpha_e_rad"]),
        )
        start = sim.render_count
        previews = hub.previews  # counted apart: images taken are what observers see
        try:
            run = calibrate_head(
                sim,
                ObservedEyeServo(sim, _servo_config(scenario)),
                ball,
                names.CALIBRATION_BALL,
                positions,
                depth_noise_m=spec.depth_noise_m,
                rng=np.random.default_rng([seed, STREAM_DEPTH_NOISE]),
                extended=spec.extended,
                position_noise_m=spec.position_noise_m,
                lines_of_sight=spec.lines_of_sight,
                knowledge=_told(scenario),
            )
        except ValueError as err:
            outcomes = err.outcomes if isinstance(err, CalibrationError) else ()
            report = replace(
                planned,
                status=Status.FAILED,
                detail=f"failed: {err}",
                renders=sim.render_count - start - (hub.previews - previews),
                fixated=sum(o is None for o in outcomes),
                positions=position_outcomes(outcomes),
            )
            hub.calibrated(report)
            return None, report
    fit, knowledge = run.fit, run.knowledge
    report = replace(
        planned,
        fixated=run.samples,
        positions=position_outcomes(run.outcomes),
        renders=run.renders - (hub.previews - previews),
        alpha_e_rad=list(fit.alpha_e),
        alpha_e_std_rad=list(fit.std_errors),
        alpha_e_covariance_rad2=np.asarray(fit.covariance).tolist(),
        alpha_e_error_rad=list(run.alpha_e_error),
        converged=bool(fit.converged),
        depth_residual_rms_m=float(np.sqrt(np.mean(np.square(fit.depth_residuals)))),
        vertical_reference=None
        if run.vertical is None
        else VerticalReference(
            v0_px=[v.v0 for v in run.vertical],
            v0_std_px=[v.v0_std for v in run.vertical],
            v0_truth_px=truth_v0,
            kx_over_ky=[v.kx_over_ky for v in run.vertical],
            kx_over_ky_std=[v.kx_over_ky_std for v in run.vertical],
            kx_over_ky_truth=truth_ratio,
        ),
        lines_of_sight=None if run.lines is None else _lines_fit(run, sim),
        knowledge=KnowledgeReport(
            alpha_e_rad=list(knowledge.alpha_e),
            v0_px=list(knowledge.v0),
            kx_over_ky=list(knowledge.kx_over_ky),
            u0_px=list(knowledge.u0),
            los_offset_m=None if knowledge.los_offset_m is None else list(knowledge.los_offset_m),
        ),
    )
    hub.calibrated(report)
    return run, report


def position_outcomes(outcomes: Sequence[Failure | None]) -> tuple[PositionOutcome, ...]:
    """Each calibration position's outcome: fixated (no failure) or the failure."""
    return tuple(PositionOutcome(o) for o in outcomes)


def _lines_fit(run: CalibrationRun, sim: HeadSim) -> LinesOfSightFit:
    """The extended line-of-sight fit beside the truth."""
    lines = run.lines
    assert lines is not None
    truth = line_of_sight_truth(sim, run.knowledge)
    return LinesOfSightFit(
        alpha_e_rad=list(lines.alpha_e),
        offset_m=list(lines.offset_m),
        std_errors_alpha_e_rad=list(lines.std_errors[:2]),
        std_errors_offset_m=list(lines.std_errors[2:]),
        offset_truth_m=list(truth.offset_m),
        covariance=np.asarray(lines.covariance).tolist(),  # (alpha_e1, alpha_e2, s1, s2)
        effective_baseline_m=lines.effective_baseline_m,
        effective_baseline_std_m=lines.effective_baseline_std_m,
        effective_baseline_truth_m=truth.effective_baseline_m,
        separable=lines.separable,
        message=lines.message,
    )


def _record(
    hub: Hub, m: Measurement, knowledge: str, step: int, time_s: float | None = None
) -> MeasurementRecord:
    record = MeasurementRecord(m, knowledge, step, time_s)
    hub.measured(record)
    return record


def _run_points(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], PointsResult]:
    """Model 2 or Model 1 on each target in turn; after a calibration, also uncalibrated."""
    procedure = scenario.experiment.procedure
    targets = scenario.scene.targets
    records = []
    with ObservedSim(hub, "default", scenario) as sim:
        hub.phase(
            "measurement", sim, knowledge, {t.name: np.array(t.position_world_m) for t in targets}
        )
        config = _servo_config(scenario)
        servo: EyeServo | NeckServo
        servo = (
            ObservedNeckServo(sim, config)
            if procedure == "model1"
            else ObservedEyeServo(sim, config)
        )
        passes = (
            [(_told(scenario), "none"), (knowledge, label)]
            if procedure == "calibration"
            else [(knowledge, label)]
        )
        for placement in targets:
            for known, known_label in passes:
                step = hub.begin(placement.name)
                sim.set_body_pose(placement.body, np.array(placement.position_world_m))
                target = marker_target(placement.name, placement.body)
                if procedure == "model1":
                    assert isinstance(servo, NeckServo)
                    m = measure_model1(sim, servo, target, known, scenario.experiment.interpolate)
                else:
                    assert isinstance(servo, EyeServo)
                    m = measure_model2(sim, servo, target, known, _model2_config(scenario))
                records.append(_record(hub, m, known_label, step))
    if procedure != "calibration":
        return records, PointsResult()
    checks = tuple(
        CheckTarget(
            name=before.measurement.name,
            error_m_uncalibrated=_error(before.measurement),
            error_m_calibrated=_error(after.measurement),
        )
        for before, after in zip(records[::2], records[1::2], strict=True)
    )
    return records, PointsResult(check_targets=checks)


def _error(m: Measurement) -> float:
    return float(np.linalg.norm(m.error_head_m)) if m.ok else float("nan")


def _stats(values: np.ndarray) -> tuple[float, float]:
    """Mean and sample standard deviation (NaN where undefined)."""
    mean = float(values.mean()) if values.size else float("nan")
    std = float(values.std(ddof=1)) if values.size > 1 else float("nan")
    return mean, std


def _run_chessboard(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], ChessboardResult]:
    """Every chosen inner corner with Model 2 (Sec. VI-A), and the squares they give."""
    scene = scenario.scene
    assert scene.chessboard is not None
    columns = CHESSBOARD_PATTERN[0]
    indices = (
        list(scene.corners)
        if scene.corners is not None
        else list(range(columns * CHESSBOARD_PATTERN[1]))
    )
    with ObservedSim(hub, "chessboard", scenario) as sim:
        sim.set_body_pose(names.CHESSBOARD, np.array(scene.chessboard.position_world_m))
        body = sim.data.body(names.CHESSBOARD)
        rotation = body.xmat.reshape(3, 3)
        truth = {
            f"corner_{k % columns}_{k // columns}": body.xpos
            + rotation
            @ np.array(
                [(k % columns) * CHESSBOARD_SQUARE_M, (k // columns) * CHESSBOARD_SQUARE_M, 0.0]
            )
            for k in indices
        }
        hub.phase("measurement", sim, knowledge, truth)
        labels = iter(truth)
        hub.step_per_target(lambda: next(labels, "corner"))
        run = measure_chessboard(
            sim,
            ObservedEyeServo(sim, _servo_config(scenario)),
            knowledge,
            _model2_config(scenario),
            CHESSBOARD_PATTERN,
            CHESSBOARD_SQUARE_M,
            indices,
        )
        steps = hub.steps
    records = [
        _record(hub, m, label, step) for m, step in zip(run.measurements, steps, strict=True)
    ]
    sides = np.concatenate([run.widths_m, run.heights_m])
    width, height, side = _stats(run.widths_m), _stats(run.heights_m), _stats(sides)
    experiment = ChessboardResult(
        pattern=list(CHESSBOARD_PATTERN),
        square_m=CHESSBOARD_SQUARE_M,
        corners=len(indices),
        corners_measured=run.measured,
        widths_m=run.widths_m,
        heights_m=run.heights_m,
        true_widths_m=run.true_widths_m,
        true_heights_m=run.true_heights_m,
        width_mean_m=width[0],
        width_std_m=width[1],
        height_mean_m=height[0],
        height_std_m=height[1],
        side_mean_m=side[0],
        side_std_m=side[1],
        paper=ChessboardPaper(
            side_mean_m=PAPER["chessboard_side_mean_m"],
            side_std_m=PAPER["chessboard_side_std_m"],
        ),
    )
    return records, experiment


def _run_relative(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], RelativeResult]:
    """The cross point with Model 2, then each object's area S1..S12 (Sec. III, VI-C)."""
    scene = scenario.scene
    assert scene.blocks is not None
    colours = {o.body: names.RELATIVE_OBJECT_COLOURS[o.body] for o in scene.objects}
    with ObservedSim(hub, "blocks", scenario) as sim:
        for placement in (scene.blocks, *scene.objects):
            sim.set_body_pose(placement.body, np.array(placement.position_world_m))
        for body in scene.parked:
            sim.set_body_pose(body, np.array(PARKED_WORLD_M))
        truth = {p.name: np.array(p.position_world_m) for p in (scene.blocks, *scene.objects)}
        hub.phase("measurement", sim, knowledge, truth)
        step = hub.begin(names.BLOCKS)
        reference = Target(names.BLOCKS, find_cross_point, lambda s: s.position(names.BLOCKS))
        run = relative_positioning(
            sim, ObservedEyeServo(sim, _servo_config(scenario)), reference, colours, knowledge
        )
        positions_head = {o.body: sim.position(o.body, "head") for o in scene.objects}
    records = [_record(hub, run.reference, label, step)]
    resolution = scenario.settings.encoder_resolution_rad
    details = run.reference.details
    comparison = run.comparison
    seen = [name for name in colours if name not in run.missing]
    margins = dict(zip(seen, comparison.margin, strict=True)) if comparison is not None else {}
    objects = tuple(
        RelativeObject(
            name=name,
            colour=colour,
            area=run.areas.get(name, 0),
            true_area=run.true_areas.get(name, 0),
            agree=name in margins and run.areas[name] == run.true_areas[name],
            margin_px=margins.get(name, float("nan")),
            gain_area=run.gain_areas.get(name, 0),
            gain_agree=name in run.gain_areas and run.gain_areas[name] == run.true_areas[name],
            columns_px=list(run.columns.get(name, (float("nan"),) * 4)),
            position_head_m=positions_head[name],
        )
        for name, colour in colours.items()
    )
    experiment = RelativeResult(
        # The whole encoder steps of the two fixations, where the lines L11..L22 are.
        alpha1_rad=round(details["gamma2_rad"] / resolution) * resolution
        if details
        else float("nan"),
        alpha2_rad=round(details["gamma1_rad"] / resolution) * resolution
        if details
        else float("nan"),
        objects=objects,
        missing=list(run.missing),
        agree=sum(o.agree for o in objects),
        disagree_outside_margin=comparison.n_disagree_outside if comparison else None,
        gain_agree=sum(o.gain_agree for o in objects),
        gain_disagree_outside_margin=run.gain_comparison.n_disagree_outside
        if run.gain_comparison
        else None,
        margin_threshold_px=comparison.threshold_px if comparison else None,
        renders=run.renders,
        paper=RelativePaper(
            alpha1_rad=PAPER["relative_alpha1_rad"],
            alpha2_rad=PAPER["relative_alpha2_rad"],
            objects=PAPER["relative_objects"],
        ),
    )
    return records, experiment


def _run_tracking(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], TrackingResult]:
    """Follow the moving target with Model 1 (neck and eyes), one fixation per time."""
    moving = scenario.scene.moving
    assert moving is not None
    times = moving.times_s
    with ObservedSim(hub, "default", scenario) as sim:
        truth = {f"{moving.name} {k + 1}": moving.position(float(t)) for k, t in enumerate(times)}
        hub.phase("measurement", sim, knowledge, truth)
        hub.watch(moving.body, moving.name)
        target = marker_target(moving.name, moving.body)
        run = track_moving_target(
            sim,
            ObservedNeckServo(sim, _servo_config(scenario)),
            target,
            moving.body,
            moving.position,
            times,
            knowledge,
        )
        steps = hub.steps
    records = [
        _record(hub, m, label, step, float(t))
        for m, step, t in zip(run.measurements, steps, times, strict=True)
    ]
    errors = run.errors_world_m
    renders = [m.renders for m in run.measurements]
    experiment = TrackingResult(
        times_s=times,
        waypoints_world_m=list(moving.waypoints_world_m),
        errors_world_m=errors,
        renders_first=renders[0] if renders else 0,
        renders_after_mean=float(np.mean(renders[1:])) if len(renders) > 1 else float("nan"),
    )
    return records, experiment


def _run_pursuit(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], PursuitResult]:
    """The live head pursues a moving target (headsim.live.procedure)."""
    from headsim.live.procedure import run_pursuit

    records, block = run_pursuit(scenario, hub, knowledge, label)
    known = {"pursuit", "per_frame", "failures", *(f.name for f in fields(PursuitFigures))}
    if set(block) - known:  # a new figure must get its field, or it would not be written
        raise KeyError(f"pursuit figures without a PursuitFigures field: {set(block) - known}")
    figures = None
    if "frames" in block:
        figures = PursuitFigures(**{f.name: block[f.name] for f in fields(PursuitFigures)})
    return records, PursuitResult(
        pursuit=block["pursuit"],
        figures=figures,
        per_frame=block.get("per_frame"),
        failures=tuple(block.get("failures", ())),
    )


RUNNERS: dict[
    str, Callable[[Scenario, Hub, HeadKnowledge, str], tuple[list[MeasurementRecord], Experiment]]
] = {
    "model2": _run_points,
    "model1": _run_points,
    "calibration": _run_points,
    "chessboard": _run_chessboard,
    "relative_positioning": _run_relative,
    "tracking": _run_tracking,
    "pursuit": _run_pursuit,
}


def calibrate_scenario(scenario: Scenario, observers: Sequence[Observer] = ()) -> CalibrationReport:
    """Only the scenario's Sec. V calibration (``headsim calibrate``): its report.

    ``status`` is OK or why it failed; ``rendered_frames`` the pixels it
    rendered, in full frames.
    """
    spec = scenario.experiment.calibration
    if spec is None or spec.source is not None:
        raise ValueError("the scenario has no calibration to run ([experiment.calibration])")
    hub = Hub(observers)
    _, report = _calibrate(scenario, hub)
    return replace(report, rendered_frames=hub.rendered_frames)


def run_scenario(scenario: Scenario, observers: Sequence[Observer] = ()) -> RunResult:
    """Run a checked scenario; the observers see every image, detection and result."""
    hub = Hub(observers)
    timing: dict[str, float] = {}
    renders = {"calibration": 0, "experiment": 0, "recording": 0}
    rendered_frames = {"calibration": 0.0, "experiment": 0.0}
    knowledge, label = _told(scenario), "none"
    calibration = None
    failures: list[str] = []
    spec = scenario.experiment.calibration
    if spec is not None and spec.source is not None:
        from headsim.active.calibration_file import read_calibration

        stored = read_calibration(spec.source, scenario.settings)
        calibration = calibration_from_block(
            stored.block,
            renders=0,
            source=CalibrationSource(
                path=str(stored.path),
                scenario=stored.scenario,
                seed=stored.seed,
                head_hash=stored.head_hash,
                renders=stored.block.get("renders"),
            ),
        )
        hub.calibrated(calibration)
        knowledge, label = stored.knowledge, "calibrated"
    elif spec is not None:
        start = time.perf_counter()
        run, calibration = _calibrate(scenario, hub)
        timing["calibration"] = time.perf_counter() - start
        renders["calibration"] = calibration.renders
        rendered_frames["calibration"] = hub.rendered_frames
        if run is None:
            failures.append(f"calibration: {calibration.status_text}")
        else:
            knowledge, label = run.knowledge, "calibrated"
    records: list[MeasurementRecord] = []
    experiment: Experiment | None = None
    if not failures:
        start = time.perf_counter()
        frames = hub.frame
        records, experiment = RUNNERS[scenario.experiment.procedure](
            scenario, hub, knowledge, label
        )
        timing["experiment"] = time.perf_counter() - start
        renders["experiment"] = hub.frame - frames
        rendered_frames["experiment"] = hub.rendered_frames - rendered_frames["calibration"]
    failures += [
        f"{r.measurement.name}: {r.measurement.status_text}"
        for r in records
        if not r.measurement.ok
    ]
    if isinstance(experiment, RelativeResult):
        failures += [f"{name}: not seen in all four images" for name in experiment.missing]
    if isinstance(experiment, PursuitResult):
        failures += list(experiment.failures)
    renders["total"] = renders["calibration"] + renders["experiment"]
    timing["total"] = sum(timing.values())
    result = RunResult(
        scenario=scenario,
        calibration=calibration,
        records=tuple(records),
        experiment=experiment,
        renders=renders,
        failures=tuple(failures),
        timing_s=timing,
        rendered_frames={
            **rendered_frames,
            "total": rendered_frames["calibration"] + rendered_frames["experiment"],
        },
        windows={"rendered": hub.windows, "missed": hub.window_misses, "previews": hub.previews},
    )
    hub.finished(result)
    return result


__all__ = [
    "PAPER",
    "Hub",
    "ObservedEyeServo",
    "ObservedNeckServo",
    "ObservedSim",
    "Observer",
    "Progress",
    "calibrate_scenario",
    "marker_target",
    "run_scenario",
]
