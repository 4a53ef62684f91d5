"""The scenario's marker targets, as the procedures take them (runner, live pursuit, benchmarks)."""

from __future__ import annotations

from headsim.active.measurement import Target
from headsim.scenario.spec import MARKER_BODIES
from headsim.vision.markers import MarkerDetector


def marker_target(name: str, body: str) -> Target:
    """A marker body of the default scene, found by its colour, named ``name``."""
    return Target(name, MarkerDetector(MARKER_BODIES[body]), lambda sim: sim.truth.position(body))


__all__ = ["marker_target"]
