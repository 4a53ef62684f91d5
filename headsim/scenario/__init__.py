"""Scenario files: TOML reading, the schema, the scene's targets and layouts, the reach check.

``load_scenario`` is importable from here (scripts use ``headsim.scenario.load_scenario``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from headsim.scenario.loading import load_scenario

__all__ = ["load_scenario"]


def __getattr__(name: str) -> Any:
    if name == "load_scenario":
        from headsim.scenario.loading import load_scenario

        return load_scenario
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
