"""headsim: a MuJoCo testbed for vergence-based active stereo vision on humanoid heads.

From Python (``docs/python.md``)::

    import headsim
    scenario = headsim.load_scenario("quickstart", fast=True)
    result = headsim.run(scenario)              # headsim.RunResult
    result.measurements                         # typed rows
    result.table()                              # pandas.DataFrame(result.table())

The names below load on first use, so ``import headsim`` stays cheap.
"""

import importlib
from typing import TYPE_CHECKING, Any

from headsim.procedures import contract as _contract
from headsim.sim.backend import choose_default_backend
from headsim.version import __version__

# MuJoCo picks its OpenGL backend when first imported: choose before that.
choose_default_backend()


def _built_in_procedures() -> None:
    importlib.import_module("headsim.procedures").discover()


# The generic layers look procedures up by name and never import them: the first lookup
# imports the built-in ones (headsim.procedures.contract).
_contract.on_first_lookup(_built_in_procedures)

if TYPE_CHECKING:
    from headsim.runs.library import load_scenario, run
    from headsim.runs.outcomes import MeasurementRow
    from headsim.runs.result import RunResult
    from headsim.scenario.spec import Scenario
    from headsim.scenario.tables import ScenarioError
    from headsim.sim.simulator import HeadSim

#: Each lazily loaded name and the module that defines it.
_LAZY = {
    "load_scenario": "headsim.runs.library",
    "run": "headsim.runs.library",
    "RunResult": "headsim.runs.result",
    "MeasurementRow": "headsim.runs.outcomes",
    "Scenario": "headsim.scenario.spec",
    "ScenarioError": "headsim.scenario.tables",
    "HeadSim": "headsim.sim.simulator",
}

__all__ = [
    "HeadSim",
    "MeasurementRow",
    "RunResult",
    "Scenario",
    "ScenarioError",
    "__version__",
    "load_scenario",
    "run",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
