"""A declared setting: one key's type, range, default, unit and meaning, in one place.

Every scenario key is declared as one of these (:class:`Setting` a number or an array of
numbers, :class:`Flag`, :class:`Choice`, :class:`Text`, :class:`Array` a list of points its
reader checks) beside the field it sets, and each table as a :class:`Section` of them; the Python checks (e.g.
:class:`headsim.sim.settings.CameraSettings`), the scenario loader's getters and
one-line errors, and the scenario-key reference are all read from the declaration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Setting:
    """One number within ``lo`` .. ``hi`` ``unit`` (``lo_open``/``hi_open``: that end
    excluded; ``integer``: whole numbers only; ``count`` > 1: an array of that many, each
    in range, e.g. one per eye).

    ``default`` is the ideal camera's (for an imperfection: the imperfection off; None:
    derived from other settings, as the principal point is from the image size, or,
    with ``optional``, left out); ``example`` a value that turns an imperfection on, for
    the generic tests that every imperfection moves a figure (None: not an
    imperfection's); ``unit_note`` is said right after the unit where a scenario's error
    says what is allowed (why the range, or what bounds it further).
    """

    name: str
    default: float | tuple[float, ...] | None
    lo: float
    hi: float
    unit: str
    meaning: str
    example: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    integer: bool = False
    count: int = 1
    optional: bool = False
    unit_note: str = ""
    required: bool = False  # with default None: the file must give it (else derived)

    @property
    def fixed_default(self) -> float:
        """The default, which is a number (TypeError where it is derived)."""
        if not isinstance(self.default, (int, float)):
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


@dataclass(frozen=True)
class Flag:
    """A key that is true or false."""

    name: str
    default: bool
    meaning: str


@dataclass(frozen=True)
class Choice:
    """A key that names one of ``choices`` (``default`` None with ``required``: the file
    must give it)."""

    name: str
    choices: tuple[str, ...]
    default: str | None
    meaning: str
    required: bool = False


@dataclass(frozen=True)
class Text:
    """A one-line string of at most ``max_length`` characters; ``what`` says what it names
    (None: any text); ``default`` None: left out, or with ``required`` the file must give it."""

    name: str
    default: str | None
    meaning: str
    max_length: int = 200
    what: str | None = None
    required: bool = False
    derived: bool = False  # with default None: the reader derives it (e.g. ``target_N``)


@dataclass(frozen=True)
class Array:
    """An array of points or pairs that its reader checks itself; ``allowed`` says what it
    takes (``required``: the file must give it, else it defaults to ``default``)."""

    name: str
    allowed: str
    meaning: str
    required: bool = False
    default: object = None


#: Any declared key.
Declared = Setting | Flag | Choice | Text | Array


@dataclass(frozen=True)
class Section:
    """A scenario table at ``path`` and its declared keys; ``many`` > 0: an array of at most
    that many tables (``[[path]]``, its keys at ``path[]``)."""

    path: str
    meaning: str
    keys: tuple[Declared, ...] = ()
    many: int = 0

    @property
    def key_path(self) -> str:
        """Where its keys are: ``path``, or ``path[]`` for an array of tables."""
        return f"{self.path}[]" if self.many else self.path
