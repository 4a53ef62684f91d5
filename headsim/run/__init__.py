"""One scenario run: the runner and its phases, events, progress, typed results, results.json, the summary and the Rerun recording.

The package is callable: ``headsim.run(scenario, seed=..., ...)`` is
:func:`headsim.run.library.run` (a package and a function cannot share the name
``headsim.run``, so the package's module object takes calls; its submodules are
reached as usual, ``headsim.run.runner``).
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallableModule(types.ModuleType):
    """This package's module type: calling it runs a scenario."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        from headsim.run.library import run

        return run(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
