"""Relative positioning of several objects (Sec. III) with real rendering."""

from __future__ import annotations

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import body_target
from headsim.head.sim_head import SimHead
from headsim.procedures.relative import relative_positioning
from headsim.sim import names
from headsim.sim.simulator import HeadSim
from headsim.vision.crosses import find_cross_point


def test_relative_positioning_places_every_object_in_its_true_area() -> None:
    with HeadSim("blocks") as sim:
        run = relative_positioning(
            SimHead(sim),
            EyeServo(sim),
            body_target(names.BLOCKS, find_cross_point),
            names.RELATIVE_OBJECT_COLOURS,
        )
        assert run.reference.ok
        assert run.missing == ()
        assert run.comparison is not None and run.comparison.n_disagree_outside == 0
        for name in names.RELATIVE_OBJECTS:
            assert run.areas[name] == run.true_areas[name] != 0
        assert len(set(run.areas.values())) >= 3  # the layout spans several areas
