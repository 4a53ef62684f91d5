"""Relative positioning: the blocks' cross point with Model 2, then each object's area
(Sec. III, VI-C)."""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import TYPE_CHECKING, cast

import numpy as np
import rerun as rr

from headsim.active.events import PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, Target
from headsim.active.relative import relative_positioning
from headsim.active.servo_types import Detector
from headsim.geometry.kinematics import head_to_world
from headsim.run.context import (
    PAPER,
    PARKED_WORLD_M,
    record_measurement,
    servo_config,
    simulator,
)
from headsim.run.events import Hub
from headsim.run.outcomes import (
    MeasurementRecord,
    RelativeObject,
    RelativePaper,
    RelativeResult,
)
from headsim.run.recording_layout import GREEN, ORANGE, RED
from headsim.run.table import cell, format_table
from headsim.scenario.registry import Procedure, register
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.vision.crosses import find_cross_point

if TYPE_CHECKING:
    from headsim.run.recording import Recorder


def run_relative(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], RelativeResult]:
    """The cross point with Model 2, then each object's area S1..S12 (Sec. III, VI-C)."""
    scene = scenario.scene
    assert scene.blocks is not None
    colours = {o.body: names.RELATIVE_OBJECT_COLOURS[o.body] for o in scene.objects}
    with simulator(hub, "blocks", scenario) as sim:
        for placement in (scene.blocks, *scene.objects):
            sim.set_body_pose(placement.body, np.array(placement.position_world_m))
        for body in scene.parked:
            sim.set_body_pose(body, np.array(PARKED_WORLD_M))
        truth = {p.name: np.array(p.position_world_m) for p in (scene.blocks, *scene.objects)}
        hub.emit(PhaseStarted("measurement", sim, knowledge, truth))
        # A cross point's detection has the status and uv the servo reads; it is never
        # windowed (only blob detectors are), so it stands in for a Detection.
        cross = cast(Detector, find_cross_point)
        reference = Target(names.BLOCKS, cross, lambda s: s.position(names.BLOCKS))
        run = relative_positioning(
            sim, EyeServo(sim, servo_config(scenario)), reference, colours, knowledge
        )  # the reference's fixation is the phase's one step
        (step,) = hub.steps
        positions_head = {o.body: sim.position(o.body, "head") for o in scene.objects}
    records = [record_measurement(hub, run.reference, label, step)]
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


def _relative_lines(e: RelativeResult, paper: bool) -> list[str]:
    headers = ["", "ours"] + (["paper"] if paper else [])
    rows = [
        [
            "alpha1 (rad)",
            cell(e.alpha1_rad, ".4f"),
            *([cell(e.paper.alpha1_rad, ".4f")] if paper else []),
        ],
        [
            "alpha2 (rad)",
            cell(e.alpha2_rad, ".4f"),
            *([cell(e.paper.alpha2_rad, ".4f")] if paper else []),
        ],
        ["objects", str(len(e.objects)), *([str(e.paper.objects)] if paper else [])],
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
        for o in e.objects
    ]
    lines += format_table(["object", "colour", "area", "true area", "agree", "margin px"], obj_rows)
    lines.append(
        f"  {e.agree} of {len(e.objects)} objects in their true areas"
        + (f"; not seen: {', '.join(e.missing)}" if e.missing else "")
    )
    return lines


def _rows(e: RelativeResult, log: Recorder) -> None:
    """The lines L11, L12, L21, L22 of the two fixations and each object's area."""
    baseline = log.scenario.settings.baseline_m
    s = log.scenario.settings
    strips, labels = [], []
    far = 2.0
    for step_index, alpha in enumerate((e.alpha1_rad, e.alpha2_rad)):
        if not math.isfinite(alpha):
            return
        for camera in (1, 2):
            sign = 1.0 if camera == 1 else -1.0
            yaw = alpha + log.effective_alpha_e[camera - 1]
            start = np.array([-sign * baseline / 2, 0.0, 0.0])
            end = start + far * np.array([sign * math.sin(yaw), 0.0, math.cos(yaw)])
            strips.append(head_to_world(np.array([start, end]), 0.0, 0.0, s.neck_d1_m, s.neck_a2_m))
            labels.append(f"L{camera}{step_index + 1}")
    log.rec.log("/world/areas/lines", rr.LineStrips3D(strips, colors=[ORANGE] * 4, labels=labels))
    objects = e.objects
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


def _missing(e: RelativeResult) -> tuple[str, ...]:
    return tuple(f"{name}: not seen in all four images" for name in e.missing)


RELATIVE_POSITIONING = register(
    Procedure(
        "relative_positioning",
        "blocks",
        run_relative,
        fields=asdict,
        summary=_relative_lines,
        failures=_missing,
        rows=_rows,
    )
)


__all__ = ["RELATIVE_POSITIONING", "run_relative"]
