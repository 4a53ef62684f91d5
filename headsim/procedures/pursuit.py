"""The ``pursuit`` scenario procedure: acquire at rest, then pursue on the live head.

The target is a marker, or a textured object of ``[scene.room]`` (a mocap body moved
along the path): the user clicks it once in camera 1's first image, then camera 1
tracks its fovea and camera 2 finds it by correlation each frame
(:class:`~headsim.active.markerless.MarkerlessPair`); its truth is the clicked surface
point carried with the object.

The head first fixates the target at rest with the paper's Model 1 servo (the
scenario's servo settings), at the first instant the target is present; the
servo's image Jacobian then serves the live gaze controller
(:mod:`headsim.live.gaze`), which runs for ``duration_s`` of simulated time.
Every estimate uses what the head knows (the scenario's calibration, if it
has one, and its ``[belief]`` of its own geometry); the truth only scores.
Results (the ``experiment`` block of results.json): the figures of the run
(time to fixation, pursuit lag, position error RMS along the path, losses and
re-acquisitions) and, per frame, time, found, image offsets, estimate, truth
and error.  Subscribers see every render; each frame is a step (``FixationStarted``) and
its record a ``PursuitFrame`` event.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from headsim.active.events import FixationStarted, PhaseStarted
from headsim.active.markerless import MarkerlessPair
from headsim.active.measurement import HeadKnowledge
from headsim.active.neck_servo import NeckServo
from headsim.active.servo_types import Detector, ServoConfig
from headsim.codec import declared, doc
from headsim.head.servo_head import ServoHead
from headsim.live.gaze import FrameRecord, PursuitFrame, PursuitRun, acquire, pursue
from headsim.live.head import LiveHead
from headsim.procedures.contract import Procedure, register
from headsim.runs.context import PARKED_WORLD_M, head
from headsim.runs.events import Hub
from headsim.runs.landing import landing, vergence_error_deg
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.surface import row_band_for
from headsim.runs.targets import marker_target
from headsim.scenario.pursuit import SECTIONS, PursuitSpec, describe
from headsim.scenario.scene import read_pursuit_scene
from headsim.scenario.spec import MARKER_BODIES, STREAM_CLICKS, Scenario
from headsim.scenario.surface_targets import Click, camera_centre, cast, click
from headsim.vision.correspondence import MatchConfig

if TYPE_CHECKING:
    from headsim.runs.recording import Recorder


@declared
class PursuitFigures:
    """The figures that score a live pursuit, over the frames on which the target was present.

    Times in s, offsets in px, position errors in W, m; NaN where undefined.
    ``ended``: why the loop ended.  ``vergence_error_*_deg``: over the frames that found
    the target, the angle between eye 2's goal ray and the direction to the point eye 1
    fixates: where its goal ray truly landed on a surface, or for a marker the ray's point
    nearest the marker's centre (truth: each eye's true pose at the frame).
    """

    frames: int = doc("frames run")
    frames_present: int = doc("frames on which the target was present")
    frames_lost: int = doc("frames the target was lost")
    losses: int = doc("times it was lost")
    reacquisitions: int = doc("times it was found again")
    saccades: int = doc("saccades made")
    time_to_fixation_s: float = doc("time to the first fixation, s")
    lag_s: float = doc("the gaze's lag behind the target, s")
    offset_rms_px: float = doc("RMS image offset from the goal, px")
    position_rms_m: float = doc("RMS position error in W along the path, m")
    position_rms_pct_of_depth: float = doc("the same, % of depth")
    position_max_m: float = doc("largest position error, m")
    ended: str = doc("why the loop ended")
    vergence_error_median_deg: float = doc(
        "median vergence error over the frames that found the target (eye 2's goal ray against where eye 1's truly landed), deg",
        default=math.nan,
    )
    vergence_error_rms_deg: float = doc("the same, RMS, deg", default=math.nan)


@declared
class PursuitResult:
    """The live pursuit: the spec as run, its figures and each frame (None when it never
    started), and why it failed, one line each; ``run``: the gaze loop's own record, for a
    study's figures beyond these (not in results.json)."""

    pursuit: dict[str, Any] = doc(
        "the pursuit spec as run (`path_kind`, `duration_s`, `frame_rate_hz`, `latency_frames`, `exposure_s`, `blur_subframes`, `mode`, `predictor`, `saccade`, ...)"
    )
    figures: PursuitFigures | None = doc(
        "the figures (their keys beside `pursuit`)", default=None, flat=True, omit_if_none=True
    )
    per_frame: dict[str, Any] | None = doc(
        "each frame: `time_s`, `found`, `offsets_px`, `encoders_rad`, `estimate_world_m`, `truth_world_m`, `error_m`, `vergence_error_deg`",
        default=None,
        omit_if_none=True,
    )
    failures: tuple[str, ...] = doc("", default=(), skip=True)
    run: PursuitRun | None = doc("", default=None, compare=False, repr=False, skip=True)

    def summary_lines(self, paper: bool = False) -> list[str]:
        """The summary's lines for a pursuit run (none when it never started)."""
        p, figures = self.pursuit, self.figures
        if figures is None:
            return []

        def f(key: str, scale: float = 1.0, fmt: str = ".2f") -> str:
            value = getattr(figures, key)
            return (
                "n/a" if value is None or not math.isfinite(value) else format(value * scale, fmt)
            )

        return [
            f"pursuit: {p.get('path_kind')} path for {p.get('duration_s')} s; {p.get('frame_rate_hz')} Hz, "
            f"latency {p.get('latency_frames')} frame(s), exposure {p.get('exposure_s')} s x {p.get('blur_subframes')} "
            f"sub-frames; gaze {p.get('mode')}, predictor {'on' if p.get('predictor') else 'off'}, saccade {p.get('saccade')}",
            f"frames {figures.frames} (target present {figures.frames_present}), lost {figures.frames_lost}, "
            f"losses {figures.losses}, re-acquisitions {figures.reacquisitions}, saccades {figures.saccades}",
            f"position error RMS along the path {f('position_rms_m', 1000)} mm = {f('position_rms_pct_of_depth')} % of "
            f"distance (max {f('position_max_m', 1000)} mm); pursuit lag {f('lag_s', 1000, '.1f')} ms; "
            f"image offset RMS {f('offset_rms_px')} px; time to fixation {f('time_to_fixation_s', 1000, '.0f')} ms",
            f"vergence error (truth: where the eyes' goal rays landed) median "
            f"{f('vergence_error_median_deg', 1, '.3f')} deg, RMS {f('vergence_error_rms_deg', 1, '.3f')} deg",
        ]

    def ok_line(self, measured: int) -> str:
        """The table's last line when no frame lost the target."""
        return f"OK: {self.figures.frames if self.figures else 0} frames, the target never lost"

    def failure_lines(self) -> tuple[str, ...]:
        """Why the pursuit failed, one line each."""
        return self.failures


def figures(
    run: PursuitRun, spec: PursuitSpec, vergence_deg: list[float] | None = None
) -> PursuitFigures:
    """The figures that score a pursuit run (all frames on which the target was present);
    ``vergence_deg``: each frame's vergence error (NaN: eye 1's ray met nothing)."""
    errors = run.errors_m
    found = [
        v
        for v, r in zip(vergence_deg or [], run.records, strict=False)
        if r.found and math.isfinite(v)
    ]
    start = spec.visibility.windows[0][0] if spec.visibility.windows else 0.0
    return PursuitFigures(
        frames=len(run.records),
        frames_present=sum(1 for r in run.records if r.truth_world_m is not None),
        frames_lost=run.frames_lost,
        losses=run.losses,
        reacquisitions=run.reacquisitions,
        saccades=sum(1 for r in run.records if r.saccade),
        time_to_fixation_s=run.time_to_fixation_s(spec.gaze.fixation_tolerance_px, start),
        lag_s=run.lag_s(),
        offset_rms_px=run.rms_offset_px(),
        position_rms_m=float(np.sqrt(np.mean(errors**2))) if errors.size else math.nan,
        position_rms_pct_of_depth=run.rms_error_pct_of_depth(),
        position_max_m=float(errors.max()) if errors.size else math.nan,
        ended=run.ended,
        vergence_error_median_deg=float(np.median(found)) if found else math.nan,
        vergence_error_rms_deg=float(np.sqrt(np.mean(np.square(found)))) if found else math.nan,
    )


def _vergence_deg(
    head: ServoHead, goals: tuple[tuple[float, float], ...], marker_world_m: np.ndarray | None
) -> float:
    """The vergence error now, degrees (truth, for scoring): eye 2's goal ray against the
    direction to the point eye 1 fixates: where its ray landed on a surface, or, for a
    marker (``marker_world_m``, its centre), its ray's point nearest the centre (a 4 mm
    sphere's front, or the wall behind when the ray passes beside it, is not what the eyes
    converge on); NaN when eye 1's met nothing."""
    one, two = landing(head.truth, 1, goals[0]), landing(head.truth, 2, goals[1])
    fixated = one.point_world_m
    if marker_world_m is not None:
        along = float(one.direction_world @ (marker_world_m - one.origin_world_m))
        fixated = one.origin_world_m + along * one.direction_world
    if fixated is None:
        return math.nan
    return vergence_error_deg(two.origin_world_m, two.direction_world, fixated)


def _per_frame(records: tuple[FrameRecord, ...], vergence_deg: list[float]) -> dict[str, Any]:
    def vec(values: list[np.ndarray | None]) -> list[Any]:
        return [None if v is None else np.asarray(v).tolist() for v in values]

    return {
        "time_s": [r.time_s for r in records],
        "found": [r.found for r in records],
        "offsets_px": vec([r.error_px for r in records]),
        "estimate_world_m": vec([r.estimate_world_m for r in records]),
        "truth_world_m": vec([r.truth_world_m for r in records]),
        "error_m": [
            None
            if r.estimate_world_m is None or r.truth_world_m is None
            else float(np.linalg.norm(r.estimate_world_m - r.truth_world_m))
            for r in records
        ],
        "encoders_rad": vec([r.encoders_rad for r in records]),
        "vergence_error_deg": [v if math.isfinite(v) else None for v in vergence_deg],
    }


def run_pursuit(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], PursuitResult]:
    """Acquire at rest, then pursue on the head the runner builds: no point records, and
    the pursuit's result.  The target is moved, and the run scored, through the head's
    truth channel.

    ``hub``: where the run's events go; ``label``: unused (the procedures' common signature).
    """
    spec = scenario.scene.pursuit
    assert spec is not None  # the reader sets it for this procedure
    room, textured = scenario.scene.room, spec.body not in MARKER_BODIES
    if textured:  # a room object, moved as a mocap body
        assert room is not None  # the reader offers a room's objects only
        room = replace(
            room,
            objects=tuple(
                replace(o, movable=True) if o.name == spec.body else o for o in room.objects
            ),
        )
    staged = replace(scenario, scene=replace(scenario.scene, room=room))
    with head(hub, "default", staged) as sim_head:
        truth = sim_head.truth  # placing the target and scoring only
        live = LiveHead(sim_head, spec.live, spec.body, spec.path, spec.visibility)
        first = next(
            (
                float(t)
                for t in spec.sample_times(live.config.period_s)
                if spec.visibility.visible(float(t))
            ),
            None,
        )
        described = describe(spec)
        if first is None:
            hub.emit(PhaseStarted("measurement", truth, knowledge, {}))
            return [], PursuitResult(
                described, failures=(f"{spec.name}: never present in the run",)
            )
        told: Click | None = None
        if textured:
            for body in MARKER_BODIES:  # markers play no part: out of every view
                truth.set_body_pose(body, np.array(PARKED_WORLD_M))
            live.advance_to(first)
            told, offset = _click_object(sim_head, spec, scenario.seed)
            if told is None:
                hub.emit(PhaseStarted("measurement", truth, knowledge, {}))
                failure = "not in camera 1's first image (hidden or out of view)"
                return [], PursuitResult(described, failures=(f"{spec.name}: {failure}",))
            live.point_offset_m = offset
        else:
            live.advance_to(first)
        present = live.target_truth(first)
        assert present is not None
        hub.emit(PhaseStarted("measurement", truth, knowledge, {spec.name: present}))
        detector: Detector = (
            marker_target(spec.name, spec.body).detector
            if told is None
            # Camera 1's first image, clicked: camera 1 tracks that fovea, camera 2
            # finds it by correlation along the believed row.
            else MarkerlessPair(
                sim_head.render(1), told.clicked_uv, row_band_for(knowledge, sim_head, spec.band_px)
            )
        )
        # Whole frames, no windows or previews: the acquisition as it has always run (a
        # markerless pair still correlates only its foveal window).
        estimator = acquire(
            live, NeckServo(sim_head, ServoConfig(windows=False)), detector, knowledge
        )
        if estimator is None:
            return [], PursuitResult(described, failures=(f"{spec.name}: not acquired at rest",))

        # The servo's goal pixels: each camera's goal column on the mean goal row.
        (u1, v1), (u2, v2) = knowledge.reference(sim_head, 1), knowledge.reference(sim_head, 2)
        goals = ((u1, (v1 + v2) / 2), (u2, (v1 + v2) / 2))
        vergence: list[float] = []

        def on_frame(record: FrameRecord) -> None:
            # At the pose the frame was taken at; a marker's centre is what the eyes fixate.
            centre = record.truth_world_m if told is None else None
            vergence.append(_vergence_deg(sim_head, goals, centre))
            hub.emit(FixationStarted(f"{spec.name} t={record.time_s:.3f}s"))  # a step per frame
            hub.emit(PursuitFrame(record))

        run = pursue(live, detector, estimator, spec.duration_s, spec.gaze, on_frame)
    return [], PursuitResult(
        described,
        figures=figures(run, spec, vergence),
        per_frame=_per_frame(run.records, vergence),
        failures=(f"{spec.name}: lost {run.losses} times",) if run.losses else (),
        run=run,
    )


def _click_object(head: ServoHead, spec: PursuitSpec, seed: int) -> tuple[Click | None, np.ndarray]:
    """The user's click on the room object ``spec.body`` in camera 1's image now, and the
    clicked surface point's offset from the object's centre (truth through ``head``'s
    channel, for placing the click and scoring; the image's size is the specification's).
    The point: where camera 1's line of sight to the object's centre first meets the
    object; None where that is another object, or too near the image's edge for a
    template."""
    world = head.truth
    centre = world.data.xpos[world.model.body(spec.body).id].copy()
    origin = camera_centre(world, 1)
    hit, _, geom = cast(world.model, world.data, origin, centre - origin)
    none = np.zeros(3)
    if hit is None or world.model.body(int(world.model.geom_bodyid[geom])).name != spec.body:
        return None, none
    told = click(world, hit, np.random.default_rng([seed, STREAM_CLICKS]), spec.click_error_px)
    size = head.camera_settings(1)
    half = MatchConfig().half_px + 2
    u, v = told.clicked_uv
    if not (half <= u <= size.width - 1 - half and half <= v <= size.height - 1 - half):
        return None, none
    return told, hit - centre


def _fixations(scenario: Scenario) -> int:
    pursuit = scenario.scene.pursuit
    assert pursuit is not None  # the reader sets it for this procedure
    return math.ceil(pursuit.duration_s * pursuit.live.frame_rate_hz)  # one per camera frame


def log_path(result: PursuitResult, log: Recorder) -> None:
    """The target's path where it is visible, drawn once (static) in the recording."""
    import rerun as rr  # only when recording: Rerun costs a third of a second to import

    from headsim.runs.recording_layout import GREY

    spec = log.scenario.scene.pursuit
    if spec is None:
        return
    times = spec.sample_times(0.02)
    path = [spec.path.position(float(t)) for t in times if spec.visibility.visible(float(t))]
    if len(path) > 1:
        log.rec.log(
            "/world/pursuit/path",
            rr.LineStrips3D([np.array(path)], colors=[GREY], labels=["path"]),
            static=True,
        )


PURSUIT = register(
    Procedure(
        "pursuit",
        "default",
        run_pursuit,
        PursuitResult,
        summary=PursuitResult.summary_lines,
        ok_line=PursuitResult.ok_line,
        failures=PursuitResult.failure_lines,
        rows=log_path,
        read_scene=read_pursuit_scene,
        fixations=_fixations,
        keys=SECTIONS,
        rank=70,
    )
)


__all__ = ["PURSUIT", "PursuitFigures", "PursuitResult", "figures", "run_pursuit"]
