"""Relative positioning: the blocks' cross point with Model 2, then each object's area
(Sec. III, VI-C)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, cast

import numpy as np

from headsim.active.events import FixationStarted, MeasurementDone, PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.active.model2 import Model2Config, measure_model2
from headsim.active.servo_types import Detector
from headsim.codec import declared, doc
from headsim.estimators.areas import (
    AreaComparison,
    areas_from_geometry,
    areas_from_pixels,
    compare_areas,
)
from headsim.head.servo_head import ServoHead
from headsim.procedures.contract import Procedure, register
from headsim.runs.context import (
    PAPER,
    PARKED_WORLD_M,
    head,
    record_measurement,
    servo_config,
)
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.table import cell, format_table
from headsim.scenario.scene import (
    POSITION,
    RANDOM_BOX,
    default_position,
    position_of,
    random_points_head,
    read_position,
    start_head_to_world,
    tuple3,
)
from headsim.scenario.spec import STREAM_OBJECTS, Placement, Scenario, SceneSpec
from headsim.scenario.tables import Context, Table
from headsim.sim import names
from headsim.sim.declared import Choice, Section, Setting
from headsim.sim.events import EventSink
from headsim.sim.model import neck_of
from headsim.sim.settings import HeadSettings
from headsim.vision.crosses import find_cross_point
from headsim.vision.detection import Detection
from headsim.vision.markers import find_markers

if TYPE_CHECKING:
    from headsim.runs.recording import Recorder


@declared
class RelativeObject:
    """One object of relative positioning: its area S1..S12 (0: none), measured and true."""

    name: str = doc("its body")
    colour: str = doc("its colour")
    area: int = doc("its measured area S1..S12 (0: none)")
    true_area: int = doc("its true area")
    agree: bool = doc("whether they agree")
    margin_px: float = doc("the area test's margin for it, px (NaN: not compared)")
    gain_area: int = doc("its area by the gain-normalised test")
    gain_agree: bool = doc("whether that agrees with the truth")
    columns_px: list[float] = doc("u11, u12, u21, u22, px")
    position_head_m: np.ndarray = doc("its true position in H, m")
    #: The gain-normalised test's distance from an area boundary, px (NaN: not compared);
    #: for studies, not written to results.json.
    gain_margin_px: float = doc("", default=math.nan, skip=True)


@declared
class RelativePaper:
    """Sec. VI-C's fixation angles, rad, and number of objects."""

    alpha1_rad: float = doc("the paper's first fixation angle, rad")
    alpha2_rad: float = doc("the paper's second fixation angle, rad")
    objects: int = doc("the paper's number of objects")


@declared
class RelativeResult:
    """Relative positioning (Sec. III, VI-C): the two fixations' angles, rad, and each object."""

    alpha1_rad: float = doc("the first fixation's encoder reading, rad")
    alpha2_rad: float = doc("the second fixation's encoder reading, rad")
    objects: tuple[RelativeObject, ...] = doc("each object")
    missing: list[str] = doc("objects not seen in all four images")
    agree: int = doc("objects whose area agrees")
    disagree_outside_margin: int | None = doc(
        "disagreements outside the margin (`null`: no threshold)"
    )
    gain_agree: int = doc("agreements by the gain-normalised test")
    gain_disagree_outside_margin: int | None = doc("its disagreements outside the margin")
    margin_threshold_px: float | None = doc("the margin, px (`null`: none)")
    renders: int = doc("renders of both fixations")
    paper: RelativePaper = doc("Sec. VI-C's `alpha1_rad`, `alpha2_rad` and `objects`")

    def failures(self) -> tuple[str, ...]:
        """Each object not seen in all four images."""
        return tuple(f"{name}: not seen in all four images" for name in self.missing)

    def summary_lines(self, paper: bool) -> list[str]:
        """The two fixations' angles (and the paper's) and each object's area."""
        headers = ["", "ours"] + (["paper"] if paper else [])
        rows = [
            [
                "alpha1 (rad)",
                cell(self.alpha1_rad, ".4f"),
                *([cell(self.paper.alpha1_rad, ".4f")] if paper else []),
            ],
            [
                "alpha2 (rad)",
                cell(self.alpha2_rad, ".4f"),
                *([cell(self.paper.alpha2_rad, ".4f")] if paper else []),
            ],
            ["objects", str(len(self.objects)), *([str(self.paper.objects)] if paper else [])],
        ]
        lines = [
            "Relative positioning (Sec. III, Table VII): fixations on the cross point",
            *format_table(headers, rows),
        ]
        obj_rows = [
            [
                o.name,
                o.colour,
                f"S{o.area}" if o.area else "-",
                f"S{o.true_area}" if o.true_area else "-",
                "yes" if o.agree else "NO",
                cell(o.margin_px, ".1f"),
            ]
            for o in self.objects
        ]
        lines += format_table(
            ["object", "colour", "area", "true area", "agree", "margin px"], obj_rows
        )
        lines.append(
            f"  {self.agree} of {len(self.objects)} objects in their true areas"
            + (f"; not seen: {', '.join(self.missing)}" if self.missing else "")
        )
        return lines

    def log_rows(self, log: Recorder) -> None:
        """The lines L11, L12, L21, L22 of the two fixations and each object's area."""
        import rerun as rr  # only when recording: Rerun costs a third of a second to import

        from headsim.runs.recording_layout import GREEN, ORANGE, RED

        baseline = log.scenario.settings.baseline_m
        s = log.scenario.settings
        strips, labels = [], []
        far = 2.0
        for step_index, alpha in enumerate((self.alpha1_rad, self.alpha2_rad)):
            if not math.isfinite(alpha):
                return
            for camera in (1, 2):
                sign = 1.0 if camera == 1 else -1.0
                yaw = alpha + log.effective_alpha_e[camera - 1]
                start = np.array([-sign * baseline / 2, 0.0, 0.0])
                end = start + far * np.array([sign * math.sin(yaw), 0.0, math.cos(yaw)])
                strips.append(
                    neck_of(s.head).head_to_world(
                        np.array([start, end]), 0.0, 0.0, s.neck_d1_m, s.neck_a2_m
                    )
                )
                labels.append(f"L{camera}{step_index + 1}")
        log.rec.log(
            "/world/areas/lines", rr.LineStrips3D(strips, colors=[ORANGE] * 4, labels=labels)
        )
        objects = self.objects
        positions = [log.truth[o.name] for o in objects if o.name in log.truth]
        log.rec.log(
            "/world/areas/objects",
            rr.Points3D(
                positions,
                radii=0.008,
                colors=[GREEN if o.agree else RED for o in objects],
                labels=[f"{o.name}: S{o.area} (true S{o.true_area})" for o in objects],
            ),
        )


@dataclass(frozen=True)
class RelativeRun:
    """Areas S1..S12 of objects around a reference, by eq. (12) on pixels and by geometry.

    ``areas``/``true_areas``: label -> area number (0: unclassified or not
    seen in all four images); ``columns``: label -> (u11, u12, u21, u22), px;
    ``comparison``: the estimator's count of disagreements by margin.
    ``gain_areas``/``gain_comparison``: the same with each camera's offsets
    divided by its gain (px per encoder step, learnt by the servo from the
    images: no intrinsics), so the magnitude tests compare angles, not pixels
    of two different focal lengths; margins in px at the mean gain.
    """

    reference: Measurement
    areas: dict[str, int]
    true_areas: dict[str, int]
    columns: dict[str, tuple[float, float, float, float]]
    missing: tuple[str, ...]
    comparison: AreaComparison | None
    renders: int
    gain_areas: dict[str, int] = field(default_factory=dict)
    gain_comparison: AreaComparison | None = None


def _touching_blobs(found: dict[str, Detection], gap_px: float = 1.5) -> set[str]:
    """Labels of blobs that touch another label's blob in the same image.

    Where one ball partly hides another, both blobs meet and the hidden one's
    centroid moves by up to its radius, which no single image can tell from a
    shift.  Radii come from the blobs' areas (px): image-only.
    """
    blobs = [
        (name, np.array(d.uv), math.sqrt(d.area_px / math.pi))
        for name, d in found.items()
        if d.found and d.uv is not None
    ]
    out = set()
    for i, (name_a, uv_a, r_a) in enumerate(blobs):
        for name_b, uv_b, r_b in blobs[:i]:
            if float(np.linalg.norm(uv_a - uv_b)) < r_a + r_b + gap_px:
                out |= {name_a, name_b}
    return out


def relative_positioning(
    head: ServoHead,
    servo: EyeServo,
    reference: Target,
    objects: dict[str, str],
    knowledge: HeadKnowledge | None = None,
    sink: EventSink | None = None,
) -> RelativeRun:
    """Measure ``reference`` with Model 2, then place ``objects`` (body -> colour) in areas.

    The four images (each camera at each step) are taken again at the two
    fixations' whole encoder steps, where the lines L11..L22 are.  An object
    whose blob touches another's in any image (one partly hides the other)
    counts as not seen: its centroid would be biased.
    ``sink``: where the reference's fixation and measurement are reported (None:
    the head's sink).
    """
    sink = head.sink if sink is None else sink
    knowledge = knowledge or HeadKnowledge()
    start = head.render_count
    sink.emit(FixationStarted(reference.name))
    ref = measure_model2(head, servo, reference, knowledge, Model2Config(midline_px=0.0))
    sink.emit(MeasurementDone(ref))
    if not ref.ok:
        return RelativeRun(ref, {}, {}, {}, tuple(objects), None, head.render_count - start)
    resolution = head.settings.encoder_resolution_rad
    # The lines L11..L22 are the cameras' lines of sight at the two fixations
    # (not where a search took a y image).
    steps = (
        round(ref.details["step1_encoder_rad"] / resolution),
        round(ref.details["step2_encoder_rad"] / resolution),
    )
    columns: dict[str, list[float]] = {name: [math.nan] * 4 for name in objects}
    # Order of the four columns: u11 (Ca1, step 1), u12 (Ca1, step 2), u21, u22.
    for step_index, step in enumerate(steps):
        head.command_eye_steps(step)
        head.settle()
        for camera in (1, 2):
            found = find_markers(head.render(camera), objects)
            touching = _touching_blobs(found)
            for name, detection in found.items():
                if detection.found and detection.uv is not None and name not in touching:
                    columns[name][2 * (camera - 1) + step_index] = detection.uv[0]
    seen = [name for name in objects if np.all(np.isfinite(columns[name]))]
    missing = tuple(name for name in objects if name not in seen)
    (u10, _), (u20, _) = knowledge.reference(head, 1), knowledge.reference(head, 2)
    alpha1, alpha2 = steps[0] * resolution, steps[1] * resolution
    areas: dict[str, int] = dict.fromkeys(objects, 0)
    true_areas: dict[str, int] = dict.fromkeys(objects, 0)
    comparison = gain_comparison = None
    gain_areas: dict[str, int] = {}
    if seen:
        cols = np.array([columns[name] for name in seen])
        u11, u12, u21, u22 = cols.T
        pixel_areas = areas_from_pixels(u11, u12, u21, u22, u10, u20, alpha1=alpha1, alpha2=alpha2)
        truth_h = np.array([head.truth.position(name, "head") for name in seen])
        effective = (
            head.truth.effective_initial_direction(1),
            head.truth.effective_initial_direction(2),
        )
        truth = areas_from_geometry(
            truth_h, alpha1, alpha2, head.truth.settings.baseline_m, effective
        )
        comparison = compare_areas(pixel_areas, truth, u11, u12, u21, u22, u10, u20)
        areas.update(zip(seen, (int(a) for a in pixel_areas), strict=True))
        true_areas.update(zip(seen, (int(a) for a in truth), strict=True))
        g1, g2 = (abs(servo.gains.get(camera) or 0.0) for camera in (1, 2))
        if g1 > 0 and g2 > 0:
            gain = areas_from_pixels(
                u11, u12, u21, u22, u10, u20, alpha1=alpha1, alpha2=alpha2, kx=(g1, g2)
            )
            mean = (g1 + g2) / 2
            scaled = cols.copy()
            scaled[:, :2] = u10 + (cols[:, :2] - u10) * mean / g1
            scaled[:, 2:] = u20 + (cols[:, 2:] - u20) * mean / g2
            s11, s12, s21, s22 = scaled.T
            gain_comparison = compare_areas(gain, truth, s11, s12, s21, s22, u10, u20)
            gain_areas = dict(zip(seen, (int(a) for a in gain), strict=True))
    return RelativeRun(
        reference=ref,
        areas=areas,
        true_areas=true_areas,
        columns={name: (c[0], c[1], c[2], c[3]) for name, c in columns.items()},
        missing=missing,
        comparison=comparison,
        renders=head.render_count - start,
        gain_areas=gain_areas,
        gain_comparison=gain_comparison,
    )


def run_relative(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], RelativeResult]:
    """The cross point with Model 2, then each object's area S1..S12 (Sec. III, VI-C)."""
    scene = scenario.scene
    assert scene.blocks is not None
    colours = {o.body: names.RELATIVE_OBJECT_COLOURS[o.body] for o in scene.objects}
    with head(hub, "blocks", scenario) as sim:
        for placement in (scene.blocks, *scene.objects):
            sim.truth.set_body_pose(placement.body, np.array(placement.position_world_m))
        for body in scene.parked:
            sim.truth.set_body_pose(body, np.array(PARKED_WORLD_M))
        truth = {p.name: np.array(p.position_world_m) for p in (scene.blocks, *scene.objects)}
        hub.emit(PhaseStarted("measurement", sim.truth, knowledge, truth))
        # A cross point's detection has the status and uv the servo reads; it is never
        # windowed (only blob detectors are), so it stands in for a Detection.
        cross = cast(Detector, find_cross_point)
        reference = Target(names.BLOCKS, cross, lambda s: s.truth.position(names.BLOCKS))
        run = relative_positioning(
            sim, EyeServo(sim, servo_config(scenario)), reference, colours, knowledge
        )  # the reference's fixation is the phase's one step
        (step,) = hub.steps
        positions_head = {o.body: sim.truth.position(o.body, "head") for o in scene.objects}
    records = [record_measurement(hub, run.reference, label, step)]
    resolution = scenario.settings.encoder_resolution_rad
    details = run.reference.details
    comparison = run.comparison
    seen = [name for name in colours if name not in run.missing]
    margins = dict(zip(seen, comparison.margin, strict=True)) if comparison is not None else {}
    gain_margins = (
        dict(zip(seen, run.gain_comparison.margin, strict=True)) if run.gain_comparison else {}
    )
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
            gain_margin_px=gain_margins.get(name, float("nan")),
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


def read_blocks(table: Table, ctx: Context, settings: HeadSettings, seed: int) -> SceneSpec:
    """``[scene.blocks]`` (the cross point) and ``[[scene.objects]]``/``[scene.random_objects]``."""
    blocks = table.section(BLOCKS) or Table({}, BLOCKS.path, ctx)
    reference = read_position(blocks, settings, default_position("blocks", names.BLOCKS))
    blocks.done()
    objects: list[Placement] = []
    for entry in table.sections(OBJECTS):
        body = entry.setting(_OBJECT)
        position = read_position(entry, settings)
        entry.done()
        if any(o.body == body for o in objects):
            raise entry.fail("body", f"{body!r} is placed twice", "each object once")
        objects.append(Placement(body, body, tuple3(position), entry.path))
    random_table = table.section(RANDOM_OBJECTS)
    if random_table is not None:
        if objects:
            raise random_table.fail(
                "count", "given together with [[scene.objects]]", "one of the two"
            )
        count = random_table.setting(_COUNT)
        rng = np.random.default_rng([seed, STREAM_OBJECTS])
        points = start_head_to_world(settings, random_points_head(random_table, count, rng))
        random_table.done()
        objects = [
            Placement(body, body, tuple3(p), f"{random_table.path} (object {k + 1})")
            for k, (body, p) in enumerate(zip(names.RELATIVE_OBJECTS, points, strict=False))
        ]
    if not objects:
        objects = [
            Placement(body, body, tuple3(default_position("blocks", body)), "scene (model default)")
            for body in names.RELATIVE_OBJECTS
        ]
    used = {o.body for o in objects}
    parked = tuple(body for body in names.RELATIVE_OBJECTS if body not in used)
    return SceneSpec(
        scene="blocks",
        blocks=Placement(names.BLOCKS, names.BLOCKS, tuple3(reference), blocks.path),
        objects=tuple(objects),
        parked=parked,
    )


#: The scenario tables only it reads.
_OBJECT = Choice("body", names.RELATIVE_OBJECTS, None, "The object body (`object_1`..`object_6`).", required=True)  # fmt: skip
_COUNT = Setting("count", None, 1, len(names.RELATIVE_OBJECTS), "", "Number of objects placed.", integer=True, required=True)  # fmt: skip
BLOCKS = Section("scene.blocks", "The blocks' cross point (procedure `relative_positioning`).", position_of("Cross point"))  # fmt: skip
OBJECTS = Section("scene.objects", "Objects measured relative to the cross point, each seen by both cameras at the start pose or in all four images at the cross point's fixations; those not listed are parked out of view.", (_OBJECT, *POSITION), many=len(names.RELATIVE_OBJECTS))  # fmt: skip
RANDOM_OBJECTS = Section("scene.random_objects", "Objects at random positions instead of `[[scene.objects]]`, drawn from the seed.", (_COUNT, *RANDOM_BOX))  # fmt: skip


RELATIVE_POSITIONING = register(
    Procedure(
        "relative_positioning",
        "blocks",
        run_relative,
        RelativeResult,
        summary=RelativeResult.summary_lines,
        failures=RelativeResult.failures,
        rows=RelativeResult.log_rows,
        read_scene=read_blocks,
        fixations=lambda scenario: 1,  # the cross point's
        keys=(BLOCKS, OBJECTS, RANDOM_OBJECTS),
        rank=60,
    )
)


__all__ = [
    "RELATIVE_POSITIONING",
    "RelativeObject",
    "RelativePaper",
    "RelativeResult",
    "RelativeRun",
    "relative_positioning",
    "run_relative",
]
