"""Relative positioning: the blocks' cross point with Model 2, then each object's area
(Sec. III, VI-C)."""

from __future__ import annotations

from typing import cast

import numpy as np

from headsim.active.events import PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, Target
from headsim.active.relative import relative_positioning
from headsim.active.servo_types import Detector
from headsim.run.events import Hub
from headsim.run.outcomes import (
    MeasurementRecord,
    RelativeObject,
    RelativePaper,
    RelativeResult,
)
from headsim.run.phases.setup import (
    PAPER,
    PARKED_WORLD_M,
    record_measurement,
    servo_config,
    simulator,
)
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.vision.crosses import find_cross_point


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


__all__ = ["run_relative"]
