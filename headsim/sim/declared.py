"""A declared setting: one number's type, range, default, unit and meaning, in one place.

A camera's settings (:mod:`headsim.sim.settings`) and every image imperfection's
(:mod:`headsim.sim.imperfections`) are declared as :class:`Setting`; the Python checks
(:class:`headsim.sim.settings.CameraSettings`), the scenario schema's checks and the
scenario-key reference's meanings are all read from the declaration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Setting:
    """One number within ``lo`` .. ``hi`` ``unit`` (``lo_open``/``hi_open``: that end
    excluded; ``integer``: whole numbers only).

    ``default`` is the ideal camera's (for an imperfection: the imperfection off; None:
    derived from other settings, as the principal point is from the image size);
    ``example`` a value that turns an imperfection on, for the generic tests that every
    imperfection moves a figure (None: not an imperfection's).
    """

    name: str
    default: float | None
    lo: float
    hi: float
    unit: str
    meaning: str
    example: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    integer: bool = False

    @property
    def fixed_default(self) -> float:
        """The default, which is a number (TypeError where it is derived)."""
        if self.default is None:
            raise TypeError(f"{self.name}'s default is derived from other settings")
        return self.default

    def allows(self, value: float) -> bool:
        """Whether ``value`` lies within the range."""
        above = value > self.lo if self.lo_open else value >= self.lo
        below = value < self.hi if self.hi_open else value <= self.hi
        return above and below

    def range_text(self) -> str:
        """The range as ``[lo, hi] unit``, a round bracket at an open end."""
        unit = f" {self.unit}" if self.unit else ""
        left, right = "(" if self.lo_open else "[", ")" if self.hi_open else "]"
        return f"{left}{self.lo:g}, {self.hi:g}{right}{unit}"

    def check(self, value: object) -> str | None:
        """Why ``value`` is not allowed (None: it is)."""
        if self.integer:
            if isinstance(value, bool) or not isinstance(value, int):
                return f"{self.name} must be an integer, got {value!r}"
        elif not (isinstance(value, (int, float)) and math.isfinite(value)):
            return f"{self.name} must be a finite number, got {value!r}"
        if not self.allows(value):
            return f"{self.name} must be within {self.range_text()}, got {value}"
        return None
