"""The procedures a scenario can name, one module each; :func:`discover` imports them all.

Each module holds a procedure's run (on the run's simulator, event hub and what
the head knows: :mod:`headsim.runs.context`), its typed result, which writes its
results.json ``experiment`` fields, its summary lines and its recording rows, and
what its keys mean, gathered in a :class:`~headsim.procedures.contract.Procedure`
it registers.  :func:`discover` imports every module of this package, so a new
module is found with no list to edit; the package root has the first lookup
(:func:`headsim.procedures.contract.get`) call it.  The runner, results.json, the
summary, the recording and the references find a procedure by name and never
name it.  CONTRIBUTING.md walks through adding one.
"""

from __future__ import annotations

import importlib
import pkgutil

from headsim.procedures.contract import REGISTRY, Procedure, get, names, register

#: This package, whose every module is a procedure (or a helper of some).
PACKAGE = "headsim.procedures"


def discover() -> None:
    """Import every module of this package (each registers its procedure)."""
    for found in pkgutil.iter_modules(__path__):
        importlib.import_module(PACKAGE + "." + found.name)


__all__ = ["REGISTRY", "Procedure", "discover", "get", "names", "register"]
