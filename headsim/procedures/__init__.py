"""The procedures a scenario can name, one module each; importing this package registers them.

Each module holds a procedure's run (on the run's simulator, event hub and what
the head knows: :mod:`headsim.run.context`) and its typed result, which writes
its results.json ``experiment`` fields, its summary lines and its recording
rows, gathered in a :class:`Procedure` given to :func:`register`.  The runner,
results.json, the summary and the recording find a procedure by name
(:func:`get`) and never name its result type.  CONTRIBUTING.md walks through
adding one.
"""

from __future__ import annotations

# isort: off
# The order of registration is the order a scenario's error lists the procedures in.
from headsim.procedures import model2, model1, calibration, tracking, chessboard
from headsim.procedures import relative, pursuit, stereo, zoom_fixed_points, fixation

# isort: on
from headsim.scenario.registry import REGISTRY, Procedure, get, names, register

__all__ = [
    "REGISTRY",
    "Procedure",
    "calibration",
    "chessboard",
    "fixation",
    "get",
    "model1",
    "model2",
    "names",
    "pursuit",
    "register",
    "relative",
    "stereo",
    "tracking",
    "zoom_fixed_points",
]
