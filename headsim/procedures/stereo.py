"""The calibrated stereo baseline: Zhang's calibration from chessboard views, then each
target triangulated at eye angle 0.

The run: the chessboard scene's board in ``views`` seeded random poses, both eyes at
eye angle 0 (:func:`headsim.stereo.views.chessboard_views`); each camera calibrated
(``calibrateCamera``, k1, k2), then the pair (``stereoCalibrate``:
:func:`headsim.stereo.calibration.calibrate_stereo`); then, in the default scene, each
of the scenario's targets found in both full frames and triangulated
(:func:`headsim.stereo.triangulation.measure_point_stereo`).  Every target's
position in H is computed with camera 1 placed in H in several ways (from the
extrinsics, and from the eye geometry: :data:`HEAD_FRAMES`).  Nothing is fixated,
so the run makes no Model 2 measurement records (each target is one step).

Its scenario block, all keys optional::

    [experiment]
    procedure = "stereo"

    [experiment.stereo]
    views = 24                  # board poses rendered (at least 5 must show the board)
    distance_m = [0.4, 1.0]     # the board centre's distance from camera 1, m
    max_tilt_rad = 0.6          # the board's tilt about its x and y axes, at most, rad
    refine_intrinsics = true    # stereoCalibrate refines each camera's K, k1, k2
    pattern = [8, 6]            # the board's inner corners (the scene's board: 8 x 6)
    # or, instead of the board keys, a stored calibration to triangulate with:
    # from = "zhang.json"       # headsim.stereo.calibration_file, relative to this file
    # look = "once"             # with from: a binned preview, then a window (or "full_frame")

    [[scene.targets]]           # what to triangulate, as for Model 2
    position_head_m = [0.0, 0.0, 0.4]

Its results.json block: the views kept and their renders, the detected corners'
errors, each camera's parameters (truth, mono, stereo), the extrinsics beside the
truth, the baseline's acceptance figure (``max_rms_px`` <= 0.2 px,
``max_abs_focal_error_pct`` <= 0.5 %, ``passed``), each way of placing camera 1 in H with its targets' worst and
mean error, and each target (truth, estimate, error in H, m, from the extrinsics).
A target not found in both images is a failure.  With ``from``, nothing is calibrated
and the block holds only ``head_frames`` and ``targets``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from headsim.active.chessboard import look_for_board
from headsim.active.events import PhaseStarted
from headsim.active.look import look_once
from headsim.active.measurement import HeadKnowledge
from headsim.codec import declared, doc
from headsim.geometry.transforms import frame_deviation
from headsim.head.servo_head import ServoHead
from headsim.procedures.contract import Procedure, register
from headsim.runs.context import head
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.table import cell, format_table, mm
from headsim.scenario.scene import targets_reader
from headsim.scenario.spec import WHEN_GIVEN, CalibrationSpec, Scenario
from headsim.scenario.tables import Table
from headsim.sim.declared import Array, Choice, Flag, Section, Setting, Text
from headsim.stereo.calibration import MIN_VIEWS, CameraCalibration, StereoCalibration
from headsim.stereo.calibration import calibrate_stereo as zhang_calibration
from headsim.stereo.calibration_file import StereoCalibrationFileError, read_stereo_calibration
from headsim.stereo.frames import head_from_cam1_from_eye
from headsim.stereo.triangulation import Look, measure_point_stereo, triangulate
from headsim.stereo.views import (
    CHESSBOARD_PATTERN,
    ChessboardViews,
    StereoError,
    chessboard_views,
)

if TYPE_CHECKING:
    from headsim.runs.recording import Recorder

#: The baseline's acceptance figure: every reprojection RMS at most this, px ...
RMS_BOUND_PX = 0.2
#: ... and every focal length within this fraction of the truth.
FOCAL_BOUND = 0.005

#: The ways camera 1 is placed in H, in the order results.json lists them
#: (:func:`head_frames`).
HEAD_FRAMES = (
    "from extrinsics",
    "eye, true mount yaw",
    "eye, effective direction",
    "eye, effective - centre ray",
    "parallel (yaw 0)",
    "truth",
)


@dataclass(frozen=True)
class StereoSpec:
    """``[experiment.stereo]``: board poses rendered, their distance range from camera 1,
    m, and tilt, rad; whether ``stereoCalibrate`` refines the intrinsics."""

    views: int = 24
    distance_m: tuple[float, float] = (0.4, 1.0)
    max_tilt_rad: float = 0.6
    refine_intrinsics: bool = True
    #: The board poses' seed (None: the scenario's seed).
    board_seed: int | None = field(default=None, metadata={WHEN_GIVEN: True})
    #: How each camera finds the board: ``"full_frame"``, or ``"windowed"`` (a preview,
    #: then a window: :func:`headsim.active.chessboard.look_for_board`).
    board_look: str = field(default="full_frame", metadata={WHEN_GIVEN: True})


#: ``[experiment.stereo] board_look``'s choices.
BOARD_LOOKS = ("full_frame", "windowed")


@dataclass(frozen=True)
class Parameter:
    """One camera parameter: the simulator's, ``calibrateCamera``'s, ``stereoCalibrate``'s."""

    truth: float
    mono: float
    stereo: float


@dataclass(frozen=True)
class HeadFrame:
    """Camera 1 placed in H one way: its pose's error, rad and m, and the targets' 3-D
    errors with it (worst in m, worst and mean as % of the true depth)."""

    label: str
    rotation_error_rad: float
    translation_error_m: float
    max_error_m: float
    max_error_pct_depth: float
    mean_error_pct_depth: float


@dataclass(frozen=True)
class StereoTarget:
    """One target triangulated with camera 1 placed in H from the extrinsics, m.

    ``status``: "ok" or why not (estimate NaN then); ``uv1_px``/``uv2_px`` its detections.
    """

    name: str
    status: str
    truth_head_m: np.ndarray
    estimate_head_m: np.ndarray
    estimate_world_m: np.ndarray
    uv1_px: tuple[float, float] | None
    uv2_px: tuple[float, float] | None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def error_head_m(self) -> np.ndarray:
        return self.estimate_head_m - self.truth_head_m

    @property
    def error_pct_depth(self) -> float:
        """3-D error as a percentage of the true depth z_h."""
        return float(100 * np.linalg.norm(self.error_head_m) / self.truth_head_m[2])


def target_lines(
    head_frames: tuple[HeadFrame, ...], targets: tuple[StereoTarget, ...]
) -> list[str]:
    """Each way of placing camera 1 in H, then each target, as tables (none without targets)."""
    if not targets:
        return []
    lines = format_table(
        ["camera 1 in H", "rot mrad", "trans mm", "max mm", "max %z", "mean %z"],
        [
            [
                f.label,
                cell(f.rotation_error_rad * 1e3, ".3f"),
                mm(f.translation_error_m, ".4f"),
                mm(f.max_error_m, ".2f"),
                cell(f.max_error_pct_depth, ".3f"),
                cell(f.mean_error_pct_depth, ".3f"),
            ]
            for f in head_frames
        ],
    )
    return lines + format_table(
        ["target", "true z mm", "|e| mm", "% z"],
        [
            [
                t.name,
                mm(float(t.truth_head_m[2]), ".1f"),
                mm(float(np.linalg.norm(t.error_head_m)), ".2f") if t.ok else t.status,
                cell(t.error_pct_depth, ".3f") if t.ok else "-",
            ]
            for t in targets
        ],
    )


def target_failures(targets: tuple[StereoTarget, ...]) -> tuple[str, ...]:
    """Each target not found in both images."""
    return tuple(f"{t.name}: {t.status}" for t in targets if not t.ok)


def triangulated_line(targets: tuple[StereoTarget, ...]) -> str:
    """The summary's OK line of a run whose every target was triangulated."""
    count = len(targets)
    return f"OK: {count} target{'' if count == 1 else 's'} triangulated, none failed"


def log_estimates(log: Recorder, targets: tuple[StereoTarget, ...]) -> None:
    """Each triangulated target's estimate in W."""
    import rerun as rr  # only when recording: Rerun costs a third of a second to import

    from headsim.runs.recording_layout import GREEN

    seen = [t for t in targets if t.ok]
    if seen:
        log.rec.log(
            "/world/stereo/estimates",
            rr.Points3D(
                [t.estimate_world_m for t in seen],
                radii=0.006,
                colors=[GREEN] * len(seen),
                labels=[f"{t.name} (stereo)" for t in seen],
            ),
        )


@declared
class StereoResult:
    """The baseline's calibration beside the truth, and its targets (module docstring).

    ``cameras``: per camera, kx, ky, cx, cy (px), k1, k2 and ``rms_px``;
    ``t_m``/``r`` OpenCV's T (camera 1's origin in camera 2's frame, m) and R.
    """

    poses: int = doc("board poses rendered")
    views: int = doc("board views kept (the whole board found in both images)")
    renders: int = doc("renders of the board views")
    corner_rms_px: float = doc("detected corners against their true projections, RMS, px")
    corner_max_px: float = doc("the same, largest, px")
    cameras: tuple[dict[str, Parameter], dict[str, Parameter]] = doc(
        "each camera's parameters (`fx`, `fy`, `cx`, `cy`, `k1`, `k2`): `truth`, `mono` (calibrateCamera) and `stereo` (stereoCalibrate)"
    )
    stereo_rms_px: float = doc("stereoCalibrate's reprojection RMS, px")
    baseline_m: float = doc("the calibrated baseline, |t|, m")
    true_baseline_m: float = doc("the true baseline, m")
    t_m: np.ndarray = doc("camera 2 from camera 1: the calibrated translation, m")
    true_t_m: np.ndarray = doc("the true translation, m")
    r: np.ndarray = doc("the calibrated rotation (3 x 3)")
    true_r: np.ndarray = doc("the true rotation (3 x 3)")
    rotation_error_rad: float = doc("angle between the calibrated and the true rotation, rad")
    max_rms_px: float = doc("the larger camera's reprojection RMS, px (acceptance: <= 0.2)")
    max_abs_focal_error_pct: float = doc(
        "the largest focal-length error against the truth, % (acceptance: <= 0.5)"
    )
    passed: bool = doc("both acceptance figures met")
    head_frames: tuple[HeadFrame, ...] = doc(
        "each way of placing camera 1 in H (`label`, `rotation_error_rad`, `translation_error_m`, `max_error_m`, `max_error_pct_depth`, `mean_error_pct_depth`)",
        whole=True,
    )
    targets: tuple[StereoTarget, ...] = doc(
        "each target (`name`, `status`, `truth_head_m`, `estimate_head_m`, `estimate_world_m`, `uv1_px`, `uv2_px`), m, px",
        whole=True,
    )
    #: The calibration itself, for a study that triangulates with it later (not in results.json).
    calibration: StereoCalibration | None = doc(
        "", default=None, compare=False, repr=False, skip=True
    )

    def failures(self) -> tuple[str, ...]:
        return target_failures(self.targets)

    def ok_line(self, measured: int) -> str:
        return triangulated_line(self.targets)

    def summary_lines(self, paper: bool) -> list[str]:
        """The calibration beside the truth, each way of placing camera 1, each target."""
        verdict = "PASS" if self.passed else "FAIL"
        lines = [
            f"Calibrated stereo (Zhang): {self.views} of {self.poses} board views kept, "
            f"{self.renders} renders; corners vs truth RMS {self.corner_rms_px:.3f} px",
            f"  max RMS {self.max_rms_px:.3f} px (<= {RMS_BOUND_PX}), max focal error "
            f"{self.max_abs_focal_error_pct:.3f} % (<= {FOCAL_BOUND * 100:g}): {verdict}",
            f"  baseline {mm(self.baseline_m, '.3f')} mm (truth {mm(self.true_baseline_m, '.3f')}),"
            f" R error {self.rotation_error_rad * 1e3:.3f} mrad",
        ]
        return lines + target_lines(self.head_frames, self.targets)

    def log_rows(self, log: Recorder) -> None:
        """Each triangulated target's estimate in W."""
        log_estimates(log, self.targets)


@dataclass(frozen=True)
class StoredStereoSpec:
    """``[experiment.stereo] from``: triangulate with the calibration in the file ``source``
    (:mod:`headsim.stereo.calibration_file`) instead of calibrating."""

    source: str
    #: How each camera looks for a target: ``"full_frame"``, or ``"once"`` (a binned
    #: preview, then a window where it shows the target: ``headsim.active.look.look_once``).
    look: str = "full_frame"


#: ``[experiment.stereo] look``'s choices (with ``from``).
LOOKS = ("full_frame", "once")


@declared
class StoredStereoResult:
    """The targets triangulated with a stored calibration (``source``): each way of placing
    camera 1 in H, each target, and (not in results.json) each target's renders."""

    source: str = doc("", skip=True)
    head_frames: tuple[HeadFrame, ...] = doc(
        "each way of placing camera 1 in H (`label`, `rotation_error_rad`, `translation_error_m`, `max_error_m`, `max_error_pct_depth`, `mean_error_pct_depth`)",
        whole=True,
    )
    targets: tuple[StereoTarget, ...] = doc(
        "each target (`name`, `status`, `truth_head_m`, `estimate_head_m`, `estimate_world_m`, `uv1_px`, `uv2_px`), m, px",
        whole=True,
    )
    target_renders: tuple[int, ...] = doc("", skip=True)

    def failures(self) -> tuple[str, ...]:
        return target_failures(self.targets)

    def ok_line(self, measured: int) -> str:
        return triangulated_line(self.targets)

    def summary_lines(self, paper: bool) -> list[str]:
        """The calibration's file, each way of placing camera 1, each target."""
        lines = [f"Stereo with a stored calibration ({Path(self.source).name})"]
        return lines + target_lines(self.head_frames, self.targets)

    def log_rows(self, log: Recorder) -> None:
        """Each triangulated target's estimate in W."""
        log_estimates(log, self.targets)


@declared
class NotCalibrated:
    """The board views left too few to calibrate from: ``reason`` says how many were kept."""

    poses: int = doc("board poses rendered")
    reason: str = doc("why the pair was not calibrated (only then, beside `poses`)")

    def failures(self) -> tuple[str, ...]:
        return (f"stereo calibration: {self.reason}",)

    def summary_lines(self, paper: bool) -> list[str]:
        return [f"Calibrated stereo (Zhang): not calibrated: {self.reason}"]

    def ok_line(self, measured: int) -> str:
        return "OK"  # never shown: a run without a calibration fails

    def log_rows(self, log: Recorder) -> None:
        return None


def camera_parameters(calib: StereoCalibration) -> tuple[dict[str, Parameter], ...]:
    """Per camera: kx, ky, cx, cy, k1, k2 and the RMS, truth beside mono and stereo."""

    def picks(c: CameraCalibration) -> dict[str, float]:
        return {
            "kx": float(c.K[0, 0]),
            "ky": float(c.K[1, 1]),
            "cx": float(c.K[0, 2]),
            "cy": float(c.K[1, 2]),
            "k1": float(c.dist[0]),
            "k2": float(c.dist[1]),
        }

    tables = []
    for mono, final in ((calib.mono1, calib.cam1), (calib.mono2, calib.cam2)):
        truth = {
            "kx": float(mono.true_K[0, 0]),
            "ky": float(mono.true_K[1, 1]),
            "cx": float(mono.true_K[0, 2]),
            "cy": float(mono.true_K[1, 2]),
            "k1": float(mono.true_dist[0]),
            "k2": float(mono.true_dist[1]),
        }
        m, s = picks(mono), picks(final)
        table = {key: Parameter(truth[key], m[key], s[key]) for key in truth}
        table["rms_px"] = Parameter(0.0, mono.rms_px, calib.stereo_rms_px)
        tables.append(table)
    return tuple(tables)


def head_frames(sim_head: ServoHead, calib: StereoCalibration) -> dict[str, np.ndarray]:
    """Ways to place camera 1 in H (:data:`HEAD_FRAMES`): from the extrinsics, and the
    paper's eye-geometry ones, which turn camera 1 about H's y by the true mount yaw; the
    true effective initial direction (what a perfect Sec. V calibration returns); that
    minus the calibrated centre-ray angle; and 0 (cameras parallel to H).  The true
    geometry is read through the head's truth channel: these score, they do not measure."""
    truth = sim_head.truth
    baseline = truth.settings.baseline_m
    effective = truth.effective_initial_direction(1)
    frames = (
        calib.head_from_cam1,
        head_from_cam1_from_eye(truth.settings.cameras[0].mount_yaw_rad, baseline),
        head_from_cam1_from_eye(effective, baseline),
        head_from_cam1_from_eye(effective - calib.cam1.centre_ray_yaw_rad, baseline),
        head_from_cam1_from_eye(0.0, baseline),
        calib.true_head_from_cam1,
    )
    return dict(zip(HEAD_FRAMES, frames, strict=True))


def head_frame(
    label: str,
    head_from_cam1: np.ndarray,
    calib: StereoCalibration,
    errors: list[tuple[float, float]],
) -> HeadFrame:
    """Camera 1 placed in H as ``head_from_cam1``, and its targets' ``errors`` (3-D error,
    m; that over the true depth)."""
    rotation, translation = frame_deviation(head_from_cam1, calib.true_head_from_cam1)
    if not errors:
        nan = float("nan")
        return HeadFrame(label, rotation, translation, nan, nan, nan)
    values = np.array(errors)
    return HeadFrame(
        label,
        rotation,
        translation,
        float(values[:, 0].max()),
        float(100 * values[:, 1].max()),
        float(100 * np.mean(values[:, 1])),
    )


def calibrate(
    sim_head: ServoHead, spec: StereoSpec, seed: int
) -> tuple[StereoCalibration, ChessboardViews]:
    """Zhang's calibration from ``spec.views`` seeded board poses shown to ``sim_head``
    (the chessboard scene); the calibration and its views."""
    views = chessboard_views(
        sim_head,
        spec.views,
        np.random.default_rng(seed if spec.board_seed is None else spec.board_seed),
        spec.distance_m,
        spec.max_tilt_rad,
        look=look_for_board if spec.board_look == "windowed" else None,
    )
    return zhang_calibration(sim_head, views, spec.refine_intrinsics), views


def measure_targets(
    scenario: Scenario,
    hub: Hub,
    knowledge: HeadKnowledge,
    calib: StereoCalibration,
    look: Look | None = None,
) -> tuple[tuple[StereoTarget, ...], tuple[HeadFrame, ...], tuple[int, ...]]:
    """Each of the scenario's targets triangulated with ``calib`` in the default scene, each
    camera looking with ``look`` (None: the full frame): the targets, each way of placing
    camera 1 in H, and each target's renders."""
    targets = scenario.scene.targets
    if not targets:
        return (), (), ()
    rows: list[StereoTarget] = []
    renders: list[int] = []
    frame_errors: dict[str, list[tuple[float, float]]] = {name: [] for name in HEAD_FRAMES}
    with head(hub, "default", scenario) as sim_head:
        world = sim_head.truth  # placing the targets and scoring only
        truth = {t.name: np.array(t.position_world_m) for t in targets}
        hub.emit(PhaseStarted("measurement", world, knowledge, truth))
        sim_head.move(eye=0.0)
        world_from_head = world.world_from_head()
        frames = head_frames(sim_head, calib)
        for placement in targets:
            hub.begin(placement.name)
            world.set_body_pose(placement.body, np.array(placement.position_world_m))
            start = sim_head.render_count
            try:
                m = measure_point_stereo(sim_head, calib, placement.body, look=look)
            except StereoError as missed:
                renders.append(sim_head.render_count - start)
                unknown = np.full(3, np.nan)
                truth_head = world.position(placement.body, "head")
                rows.append(
                    StereoTarget(
                        placement.name, str(missed), truth_head, unknown, unknown, None, None
                    )
                )
                continue
            renders.append(sim_head.render_count - start)
            for name, head_from_cam1 in frames.items():
                p_head = triangulate(calib, np.array([m.uv1]), np.array([m.uv2]), head_from_cam1)
                error_m = float(np.linalg.norm(p_head[0] - m.true_p_head))
                frame_errors[name].append((error_m, error_m / float(m.true_p_head[2])))
            rows.append(
                StereoTarget(
                    placement.name,
                    "ok",
                    m.true_p_head,
                    m.p_head,
                    world_from_head[:3, :3] @ m.p_head + world_from_head[:3, 3],
                    m.uv1,
                    m.uv2,
                )
            )
    summary = tuple(
        head_frame(name, head_from_cam1, calib, frame_errors[name])
        for name, head_from_cam1 in frames.items()
    )
    return tuple(rows), summary, tuple(renders)


def run_stereo(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], StereoResult | NotCalibrated | StoredStereoResult]:
    """Calibrate the pair from board views (or read ``from``'s calibration), then
    triangulate each target (module docstring)."""
    spec = scenario.experiment.block
    if isinstance(spec, StoredStereoSpec):
        stored = read_stereo_calibration(spec.source)
        look: Look | None = look_once if spec.look == "once" else None
        rows, summary, renders = measure_targets(scenario, hub, knowledge, stored, look)
        return [], StoredStereoResult(spec.source, summary, rows, renders)
    assert isinstance(spec, StereoSpec)
    with head(hub, "chessboard", scenario) as sim_head:
        hub.emit(PhaseStarted("board views", sim_head.truth, knowledge, {}))
        try:
            calib, views = calibrate(sim_head, spec, scenario.seed)
        except StereoError as error:
            return [], NotCalibrated(spec.views, str(error))
    rows, summary, _ = measure_targets(scenario, hub, knowledge, calib)
    corner_errors = views.corner_errors_px()
    focal_errors = [
        e
        for cam in (calib.mono1, calib.mono2, calib.cam1, calib.cam2)
        for e in cam.focal_rel_errors
    ]
    max_rms = max(calib.mono1.rms_px, calib.mono2.rms_px, calib.stereo_rms_px)
    max_focal = max(abs(e) for e in focal_errors)
    cameras = camera_parameters(calib)
    result = StereoResult(
        poses=views.poses_tried,
        views=views.count,
        renders=views.renders,
        corner_rms_px=float(np.sqrt(np.mean(corner_errors**2))),
        corner_max_px=float(corner_errors.max()),
        cameras=(cameras[0], cameras[1]),
        stereo_rms_px=calib.stereo_rms_px,
        baseline_m=calib.baseline_m,
        true_baseline_m=calib.true_baseline_m,
        t_m=calib.T,
        true_t_m=calib.true_cam2_from_cam1[:3, 3],
        r=calib.R,
        true_r=calib.true_cam2_from_cam1[:3, :3],
        rotation_error_rad=calib.rotation_error_rad,
        max_rms_px=max_rms,
        max_abs_focal_error_pct=max_focal * 100,
        passed=max_rms <= RMS_BOUND_PX and max_focal <= FOCAL_BOUND,
        head_frames=summary,
        targets=rows,
        calibration=calib,
    )
    return [], result


# fmt: off
_FROM = Text("from", None, "A stored stereo calibration file (`headsim.stereo.calibration_file`) to triangulate with instead of calibrating (no board keys then).", max_length=1000)
_LOOK = Choice("look", LOOKS, "full_frame", "With `from`: each camera's look for a target, the full frame or `once` (a binned preview, then a window where it shows the target).")
_VIEWS = Setting("views", StereoSpec.views, MIN_VIEWS, 1000, "", "Chessboard poses rendered for the calibration (at least 5 must show the whole board).", integer=True)
_DISTANCE = Setting("distance_m", StereoSpec.distance_m, 0.1, 5.0, "m", "The board centre's distance from camera 1, [low, high], m.", count=2)
_TILT = Setting("max_tilt_rad", StereoSpec.max_tilt_rad, 0.0, 1.2, "rad", "The board's largest tilt about its x and y axes, rad.")
_REFINE = Flag("refine_intrinsics", StereoSpec.refine_intrinsics, "stereoCalibrate refines each camera's K, k1, k2 (false: keeps each camera's own calibration).")
_SEED = Setting("board_seed", None, 0, 2**32 - 1, "", "The board poses' seed (default: the scenario's seed), so that a study can calibrate with the poses it drew before.", integer=True, optional=True)
_BOARD_LOOK = Choice("board_look", BOARD_LOOKS, StereoSpec.board_look, "How each camera finds the board: `full_frame`, or `windowed` (a binned preview, then a window on the board: the same corners).")
_PATTERN = Array("pattern", f"[{CHESSBOARD_PATTERN[0]}, {CHESSBOARD_PATTERN[1]}] (the chessboard scene's inner corners)", "The board's inner corners, [columns, rows]: the chessboard scene's board, [8, 6].", default=CHESSBOARD_PATTERN)
#: ``[experiment.stereo]``: a calibration from board views, or a stored one (``from``).
STEREO_TABLE = Section("experiment.stereo", "The calibrated stereo baseline (procedure `stereo`): Zhang's calibration from chessboard views, then each target triangulated at eye angle 0.", (_FROM, _LOOK, _VIEWS, _DISTANCE, _TILT, _REFINE, _SEED, _BOARD_LOOK, _PATTERN))
# fmt: on
#: The keys of ``[experiment.stereo]`` that only a calibration from board views reads.
BOARD_KEYS = tuple(
    d.name for d in (_VIEWS, _DISTANCE, _TILT, _REFINE, _PATTERN, _SEED, _BOARD_LOOK)
)


def _stored_spec(stereo: Table, source: str) -> StoredStereoSpec:
    """``from``: the stored calibration's file (relative to the scenario file), read and
    checked now so that a bad file fails the scenario, not the run."""
    for key in BOARD_KEYS:
        if key in stereo.data:
            raise stereo.fail(key, "given with from", "no board keys with a stored calibration")
    path = Path(source)
    if not path.is_absolute():
        path = Path(stereo.ctx.source).parent / path
    try:
        read_stereo_calibration(path)
    except StereoCalibrationFileError as err:
        raise stereo.fail("from", str(err), "a stereo calibration file") from err
    look = stereo.setting(_LOOK)
    stereo.done()
    return StoredStereoSpec(str(path), look)


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment.stereo]``: the board views (:class:`StereoSpec`), and the pattern; or ``from``, a stored calibration (:class:`StoredStereoSpec`)."""
    stereo = table.section(STEREO_TABLE) or Table({}, table.field("stereo"), table.ctx)
    source = stereo.setting(_FROM)
    if source is not None:
        return {"block": _stored_spec(stereo, source)}
    if stereo.has(_LOOK.name):
        raise stereo.fail("look", "given without from", "look with a stored calibration only")
    views = stereo.setting(_VIEWS)
    low, high = stereo.setting(_DISTANCE)
    if low > high:
        raise stereo.fail(
            "distance_m", f"[{low:g}, {high:g}] is reversed", "[low, high], low <= high"
        )
    tilt, refine = stereo.setting(_TILT), stereo.setting(_REFINE)
    board_seed, board_look = stereo.setting(_SEED), stereo.setting(_BOARD_LOOK)
    pattern = stereo.data.get(_PATTERN.name, list(CHESSBOARD_PATTERN))
    stereo.has(_PATTERN.name)
    if pattern != list(CHESSBOARD_PATTERN):
        raise stereo.fail(_PATTERN.name, f"{pattern!r} is not the scene's board", _PATTERN.allowed)
    stereo.done()
    return {"block": StereoSpec(views, (low, high), tilt, refine, board_seed, board_look)}


STEREO = register(
    Procedure(
        "stereo",
        "default",
        run_stereo,
        # A StereoResult, NotCalibrated where the views were too few, or a StoredStereoResult
        # with a stored calibration.
        (StereoResult, NotCalibrated, StoredStereoResult),
        summary=lambda result, paper: result.summary_lines(paper),
        ok_line=lambda result, measured: result.ok_line(measured),
        failures=lambda result: result.failures(),
        rows=lambda result, log: result.log_rows(log),
        options=read_options,
        read_scene=targets_reader("stereo", required=False),
        keys=(STEREO_TABLE,),
        rank=80,
    )
)


__all__ = [
    "BOARD_KEYS",
    "FOCAL_BOUND",
    "HEAD_FRAMES",
    "LOOKS",
    "RMS_BOUND_PX",
    "STEREO",
    "HeadFrame",
    "NotCalibrated",
    "Parameter",
    "StereoResult",
    "StereoSpec",
    "StereoTarget",
    "StoredStereoResult",
    "StoredStereoSpec",
    "calibrate",
    "camera_parameters",
    "head_frame",
    "head_frames",
    "log_estimates",
    "measure_targets",
    "run_stereo",
    "target_lines",
]
