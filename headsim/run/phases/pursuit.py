"""The live head pursuing a moving target (:mod:`headsim.run.live_pursuit`), typed."""

from __future__ import annotations

from dataclasses import fields

from headsim.active.measurement import HeadKnowledge
from headsim.run.events import Hub
from headsim.run.outcomes import (
    MeasurementRecord,
    PursuitFigures,
    PursuitResult,
)
from headsim.scenario.spec import Scenario


def run_pursuit_phase(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], PursuitResult]:
    """The live head pursues a moving target (headsim.run.live_pursuit)."""
    from headsim.run.live_pursuit import run_pursuit

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


__all__ = ["run_pursuit_phase"]
