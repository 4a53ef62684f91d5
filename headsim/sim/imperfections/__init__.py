"""Image imperfections, one module each (:mod:`.base` says what one is).

Importing this package registers every imperfection module in it: each registers
itself; none is listed here.
"""

from __future__ import annotations

import importlib
import pkgutil

from headsim.sim.imperfections.base import (
    NOTHING,
    Imperfection,
    Setting,
    Shot,
    Stages,
    all_settings,
    finish,
    meanings,
    prepare,
    register,
    registered,
    setting,
    unregister,
)

for _module in sorted(m.name for m in pkgutil.iter_modules(__path__)):
    if _module != "base":
        importlib.import_module(f"{__name__}.{_module}")

__all__ = [
    "NOTHING",
    "Imperfection",
    "Setting",
    "Shot",
    "Stages",
    "all_settings",
    "finish",
    "meanings",
    "prepare",
    "register",
    "registered",
    "setting",
    "unregister",
]
