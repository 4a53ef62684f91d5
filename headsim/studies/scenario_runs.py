"""A study's experiment through the runner: its head as a preset, and what the head is told.

A study states its experiment as scenario tables
(:func:`headsim.scenario.loading.scenario_from_document`) and runs it with
:func:`headsim.run.runner.run_scenario`.  What the head already knows (a
calibration the study made) reaches the run the way a user's does: as a
calibration file that the scenario names (``experiment.calibration.from``).
"""

from __future__ import annotations

from pathlib import Path

from headsim.active.calibration_file import write_calibration
from headsim.active.measurement import HeadKnowledge
from headsim.sim.settings import PRESETS, HeadSettings


def preset_of(settings: HeadSettings) -> str:
    """The name of the preset whose head is ``settings`` (ValueError if none is)."""
    for name, make in PRESETS.items():
        if make(seed=settings.seed) == settings:
            return name
    raise ValueError(
        "the head is no preset's: describe it in the scenario's [head], [cam1] and [cam2]"
    )


def knowledge_file(path: Path, settings: HeadSettings, knowledge: HeadKnowledge) -> Path:
    """Write a calibration file at ``path`` telling the head ``settings`` ``knowledge``.

    The file holds the knowledge alone (no ball layout, no fit): what
    ``experiment.calibration.from`` reads.  A knowledge with its own ``belief``
    cannot be written (the file holds no head geometry).
    """
    if knowledge.belief is not None:
        raise ValueError("a calibration file holds no belief of the head's geometry")
    block = {
        "status": "ok",
        "targets": 0,
        "fixated": 0,
        "positions": [],
        "knowledge": {
            "alpha_e_rad": list(knowledge.alpha_e),
            "v0_px": list(knowledge.v0),
            "kx_over_ky": list(knowledge.kx_over_ky),
            "u0_px": list(knowledge.u0),
            "los_offset_m": None
            if knowledge.los_offset_m is None
            else list(knowledge.los_offset_m),
        },
    }
    return write_calibration(path, settings, block, "told", settings.seed)


__all__ = ["knowledge_file", "preset_of"]
