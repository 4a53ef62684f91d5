"""Reading TOML tables: typed getters that check each value, and the error they raise.

A :class:`Table` wraps one TOML table; each getter checks one key's type and
range and names the field and what is allowed when it is wrong
(:class:`ScenarioError`: ``FILE: FIELD: what is wrong (allowed: ...)``);
:meth:`Table.setting` reads a declared key (:mod:`headsim.sim.declared`) with the getter
its declaration calls for; :meth:`Table.done` rejects the keys no getter asked for.
"""

from __future__ import annotations

import math
from typing import Any

from headsim.errors import BadInput
from headsim.sim.declared import Array, Choice, Declared, Flag, Section, Setting, Text

MISSING = object()


class ScenarioError(BadInput, ValueError):
    """A scenario file is wrong; the message names the file, the field and what is allowed."""

    def __init__(self, source: str, field_path: str, message: str, allowed: str | None = None):
        self.source, self.field, self.problem, self.allowed = source, field_path, message, allowed
        where = f"{source}: {field_path}: " if field_path else f"{source}: "
        super().__init__(where + message + (f" (allowed: {allowed})" if allowed else ""))


class TargetRefused(ScenarioError):
    """A scenario the reach check refuses: a target, corner, object or path point that the
    head cannot fixate (``code``: the reason, :data:`headsim.scenario.spec.REFUSAL_REASONS`).

    Bad input like any :class:`ScenarioError`; a sweep, whose file set the fields
    right, records it as the failure of the one job whose values lead to it.
    """

    def __init__(
        self, source: str, field_path: str, message: str, allowed: str | None, code: str
    ) -> None:
        super().__init__(source, field_path, message, allowed)
        self.code = code


def short_value(value: Any) -> str:
    """A value for a message: long integers and strings shortened."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**15:
        return f"{'-' if value < 0 else ''}an integer of {len(str(abs(value)))} digits"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def describe_value(value: Any) -> str:
    kind = {bool: "boolean", int: "integer", float: "number", str: "string"}.get(type(value))
    if kind == "integer" and abs(value) >= 10**15:
        return short_value(value)
    if kind:
        return f"{kind} {short_value(value)}"
    if isinstance(value, list):
        return f"array of {len(value)}"
    if isinstance(value, dict):
        return "table"
    return type(value).__name__


def declared_default(decl: Declared) -> Any:
    """What a getter returns for ``decl``'s key when the file leaves it out (MISSING: the
    file must give it, or the caller passes a default derived from other keys)."""
    if isinstance(decl, Flag):
        return decl.default
    if isinstance(decl, Array):
        return MISSING if decl.required else decl.default
    if isinstance(decl, Setting):
        return None if decl.optional else MISSING if decl.default is None else decl.default
    return MISSING if decl.required else decl.default


def declared_use(decl: Declared) -> tuple[str, str]:
    """``decl``'s kind and what it allows, as the getter that reads it says them."""
    if isinstance(decl, Flag):
        return "boolean", "true, false"
    if isinstance(decl, Array):
        return "array", decl.allowed
    if isinstance(decl, Choice):
        return "choice", ", ".join(decl.choices)
    if isinstance(decl, Text):
        return "string", _text_allowed(decl.max_length, decl.what)
    if decl.integer:
        return "integer", _integer_allowed(int(decl.lo), int(decl.hi))
    each = _range_text(decl.lo, decl.hi, decl.lo_open, decl.hi_open, _unit_text(decl))
    if decl.count > 1:
        return "numbers", _numbers_allowed(decl.count, each)
    return "number", f"a number {each}"


def _unit_text(setting: Setting) -> str:
    return setting.unit + setting.unit_note


def _integer_allowed(lo: int, hi: int) -> str:
    return f"an integer from {lo} to {hi}"


def _text_allowed(max_length: int, what: str | None) -> str:
    return (what or "one line of text") + f", at most {max_length} characters"


def _numbers_allowed(length: int, each: str) -> str:
    return f"an array of {length} numbers, each {each}"


def _range_text(lo: float | None, hi: float | None, lo_open: bool, hi_open: bool, unit: str) -> str:
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {hi:g}")
    text = " and ".join(parts) if parts else "any finite value"
    return f"{text} {unit}".rstrip()


def toml_value(value: Any) -> str:
    if value is MISSING:
        return ""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return str(value)


class Context:
    """Where a document came from, for messages: the file and the fields ``--fast`` set."""

    def __init__(self, source: str, fast_doc: dict[str, Any] | None) -> None:
        self.source = source
        self.fast_doc = fast_doc or {}

    def field_name(self, path: str) -> str:
        """``path``, prefixed with ``fast.`` when the value came from the ``[fast]`` table."""
        node: Any = self.fast_doc
        for part in path.replace("]", "").replace("[", ".").split("."):
            if isinstance(node, dict) and part in node:
                node = node[part]
            elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
                node = node[int(part)]
            else:
                return path
        return f"fast.{path}"

    def error(self, path: str, message: str, allowed: str | None = None) -> ScenarioError:
        return ScenarioError(self.source, self.field_name(path), message, allowed)


class Table:
    """One TOML table: typed getters that check values, then :meth:`done` rejects the rest."""

    def __init__(self, data: dict[str, Any], path: str, ctx: Context) -> None:
        self.data, self.path, self.ctx = data, path, ctx
        self.known: list[str] = []

    def field(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        if key not in self.known:
            self.known.append(key)
        return key in self.data

    def _get(self, key: str) -> Any:
        return self.data[key] if self.has(key) else MISSING

    def fail(self, key: str, message: str, allowed: str | None = None) -> ScenarioError:
        return self.ctx.error(self.field(key), message, allowed)

    def setting(
        self,
        decl: Declared,
        default: Any = MISSING,
        *,
        hi: float | None = None,
        choices: tuple[str, ...] | None = None,
    ) -> Any:
        """``decl``'s key, read and checked as declared (``default``: instead of the
        declared one, e.g. a preset's or one from the scenario's seed; ``hi``: a tighter
        upper end that depends on other keys; ``choices``: those the scene offers, e.g.
        the room's objects besides the markers)."""
        if default is MISSING:
            default = declared_default(decl)
        if isinstance(decl, Flag):
            return self.boolean(decl.name, default)
        if isinstance(decl, Array):
            raise TypeError(f"{decl.name}: an array's reader checks it")
        if isinstance(decl, Choice):
            return self.choice(decl.name, choices or decl.choices, default)
        if isinstance(decl, Text):
            return self.string(decl.name, default, decl.max_length, decl.what)
        if decl.integer:
            return self.integer(decl.name, default, int(decl.lo), int(decl.hi))
        limits: dict[str, Any] = dict(
            lo=decl.lo,
            hi=decl.hi if hi is None else hi,
            lo_open=decl.lo_open,
            hi_open=decl.hi_open,
            unit=_unit_text(decl),
        )
        if decl.count > 1:
            return self.numbers(decl.name, decl.count, default, **limits)
        return self.number(decl.name, default, **limits)

    def number(
        self,
        key: str,
        default: Any = MISSING,
        lo: float | None = None,
        hi: float | None = None,
        *,
        lo_open: bool = False,
        hi_open: bool = False,
        unit: str = "",
    ) -> float:
        value = self._get(key)
        allowed = f"a number {_range_text(lo, hi, lo_open, hi_open, unit)}"
        if value is MISSING:
            if default is MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        return self._check_number(key, value, lo, hi, lo_open, hi_open, allowed)

    def _check_number(
        self,
        key: str,
        value: Any,
        lo: float | None,
        hi: float | None,
        lo_open: bool,
        hi_open: bool,
        allowed: str,
    ) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(key, f"must be a number, got {describe_value(value)}", allowed)
        try:
            value = float(value)
        except OverflowError:  # an integer beyond 1.8e308
            raise self.fail(key, f"{short_value(value)} is out of range", allowed) from None
        bad = (
            not math.isfinite(value)
            or (lo is not None and (value <= lo if lo_open else value < lo))
            or (hi is not None and (value >= hi if hi_open else value > hi))
        )
        if bad:
            raise self.fail(key, f"{value:g} is out of range", allowed)
        return value + 0.0  # -0.0 is 0: a range [-x, x] of it must not come out reversed

    def points(
        self, decl: Array, minimum: int, maximum: int, bound_m: float
    ) -> tuple[tuple[float, float, float], ...]:
        """``decl``'s array of ``minimum`` to ``maximum`` points [x, y, z], each coordinate
        within +-``bound_m``, m."""
        key, value, allowed = decl.name, self.data.get(decl.name), decl.allowed
        self.has(key)
        if not isinstance(value, list) or not minimum <= len(value) <= maximum:
            raise self.fail(key, "missing" if value is None else "wrong length or type", allowed)
        points: list[tuple[float, float, float]] = []
        for i, p in enumerate(value):
            if not (isinstance(p, list) and len(p) == 3):
                raise self.fail(f"{key}[{i}]", "must be [x, y, z]", allowed)
            x, y, z = (
                self._check_number(f"{key}[{i}]", c, -bound_m, bound_m, False, False, allowed)
                for c in p
            )
            points.append((x, y, z))
        return tuple(points)

    def integer(self, key: str, default: Any = MISSING, lo: int = 0, hi: int = 10**6) -> int:
        value = self._get(key)
        allowed = _integer_allowed(lo, hi)
        if value is MISSING:
            if default is MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"must be an integer, got {describe_value(value)}", allowed)
        if not lo <= value <= hi:
            raise self.fail(key, f"{short_value(value)} is out of range", allowed)
        return value

    def boolean(self, key: str, default: bool) -> bool:
        value = self._get(key)
        if value is MISSING:
            return default
        if not isinstance(value, bool):
            raise self.fail(
                key, f"must be true or false, got {describe_value(value)}", "true, false"
            )
        return value

    def string(
        self, key: str, default: Any = MISSING, max_length: int = 200, what: str | None = None
    ) -> str:
        """A one-line string; ``what`` says what it names (an error's "allowed" text)."""
        value = self._get(key)
        allowed = _text_allowed(max_length, what)
        if value is MISSING:
            if default is MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        if not isinstance(value, str):
            raise self.fail(key, f"must be a string, got {describe_value(value)}", allowed)
        if not value.strip() or "\n" in value or len(value) > max_length:
            raise self.fail(key, "must be one non-empty line", allowed)
        return value

    def choice(self, key: str, allowed: tuple[str, ...] | list[str], default: Any = MISSING) -> str:
        value = self._get(key)
        text = ", ".join(allowed)
        if value is MISSING:
            if default is MISSING:
                raise self.fail(key, "missing", text)
            return default
        if not isinstance(value, str):
            raise self.fail(key, f"must be a string, got {describe_value(value)}", text)
        if value not in allowed:
            raise self.fail(key, f"unknown value {short_value(value)}", text)
        return value

    def numbers(
        self,
        key: str,
        length: int,
        default: Any = MISSING,
        lo: float | None = None,
        hi: float | None = None,
        *,
        lo_open: bool = False,
        hi_open: bool = False,
        unit: str = "",
    ) -> tuple[float, ...]:
        value = self._get(key)
        each = _range_text(lo, hi, lo_open, hi_open, unit)
        allowed = _numbers_allowed(length, each)
        if value is MISSING:
            if default is MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        if not isinstance(value, list) or len(value) != length:
            raise self.fail(
                key, f"must be an array of {length} numbers, got {describe_value(value)}", allowed
            )
        return tuple(
            self._check_number(f"{key}[{i}]", v, lo, hi, lo_open, hi_open, allowed)
            for i, v in enumerate(value)
        )

    def section(self, section: Section) -> Table | None:
        """``section``'s table below this one (None: not given)."""
        return self.table(section.path.rsplit(".", 1)[-1])

    def sections(self, section: Section) -> list[Table]:
        """``section``'s array of tables below this one (empty: not given)."""
        return self.tables(section.path.rsplit(".", 1)[-1], section.many)

    def table(self, key: str) -> Table | None:
        value = self._get(key)
        if value is MISSING:
            return None
        if not isinstance(value, dict):
            raise self.fail(
                key, f"must be a table, got {describe_value(value)}", f"a [{self.field(key)}] table"
            )
        return Table(value, self.field(key), self.ctx)

    def tables(self, key: str, max_count: int = 1000) -> list[Table]:
        value = self._get(key)
        if value is MISSING:
            return []
        allowed = f"an array of tables, [[{self.field(key)}]], at most {max_count}"
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self.fail(
                key, f"must be an array of tables, got {describe_value(value)}", allowed
            )
        if len(value) > max_count:
            raise self.fail(key, f"has {len(value)} entries", allowed)
        return [Table(v, f"{self.field(key)}[{i}]", self.ctx) for i, v in enumerate(value)]

    def done(self) -> None:
        """Reject keys that no getter asked for."""
        for key in self.data:
            if key not in self.known:
                raise self.fail(key, "unknown key", ", ".join(self.known) or "none")
