"""Typed TOML getters (scenario/tables.py): each names the field and what is allowed."""

from __future__ import annotations

import pytest

from headsim.errors import BadInput
from headsim.scenario.tables import Context, ScenarioError, Table, describe_value, short_value


def _table(data: dict, fast: dict | None = None) -> Table:
    return Table(data, "head", Context("case.toml", fast))


def _message(call) -> str:
    with pytest.raises(ScenarioError) as caught:
        call()
    return str(caught.value)


def test_the_error_is_bad_input_and_reads_file_field_problem_allowed() -> None:
    error = ScenarioError("a.toml", "head.kx", "is wrong", "a number > 0")
    assert isinstance(error, BadInput) and isinstance(error, ValueError)
    assert str(error) == "a.toml: head.kx: is wrong (allowed: a number > 0)"
    assert str(ScenarioError("a.toml", "", "not TOML")) == "a.toml: not TOML"
    assert (error.source, error.field, error.problem, error.allowed) == (
        "a.toml",
        "head.kx",
        "is wrong",
        "a number > 0",
    )


def test_values_are_described_short() -> None:
    assert short_value(10**20) == "an integer of 21 digits"
    assert short_value(-(10**20)) == "-an integer of 21 digits"
    assert short_value("x" * 100) == repr("x" * 100)[:57] + "..."
    assert describe_value(True) == "boolean True" and describe_value(2.5) == "number 2.5"
    assert describe_value([1, 2]) == "array of 2" and describe_value({}) == "table"
    assert describe_value(10**16) == "an integer of 17 digits"


def test_numbers_are_checked_against_their_range_with_the_unit() -> None:
    table = _table({"kx": 0.0, "d": -0.0, "n": True, "big": 2**1100, "v": [1.0, "a"]})
    assert table.number("d", lo=-1, hi=1) == 0.0
    assert str(table.number("d", lo=-1, hi=1)) == "0.0"  # -0.0 comes out as 0.0
    assert _message(lambda: table.number("kx", lo=0, lo_open=True, unit="px")) == (
        "case.toml: head.kx: 0 is out of range (allowed: a number > 0 px)"
    )
    assert "must be a number, got boolean True" in _message(lambda: table.number("n"))
    assert "an integer of 332 digits is out of range" in _message(lambda: table.number("big"))
    assert table.number("absent", 7.0) == 7.0
    assert "head.absent: missing (allowed: a number <= 3)" in _message(
        lambda: table.number("absent", hi=3)
    )
    assert "head.v[1]: must be a number, got string 'a'" in _message(lambda: table.numbers("v", 2))
    assert "must be an array of 3 numbers, got array of 2" in _message(
        lambda: table.numbers("v", 3)
    )


def test_integers_booleans_strings_choices_and_tables() -> None:
    table = _table(
        {"i": 3, "f": 3.0, "b": 1, "s": "two\nlines", "c": "fast", "t": {"x": 1}, "ts": [{}, {}]}
    )
    assert table.integer("i", lo=1, hi=3) == 3
    assert "from 4 to 9" in _message(lambda: table.integer("i", lo=4, hi=9))
    assert "must be an integer, got number 3.0" in _message(lambda: table.integer("f"))
    assert "must be true or false, got integer 1" in _message(lambda: table.boolean("b", False))
    assert "must be one non-empty line" in _message(lambda: table.string("s"))
    assert "unknown value 'fast' (allowed: ideal, paper)" in _message(
        lambda: table.choice("c", ("ideal", "paper"))
    )
    inner = table.table("t")
    assert inner is not None and inner.field("x") == "head.t.x"
    assert [t.path for t in table.tables("ts")] == ["head.ts[0]", "head.ts[1]"]
    assert "has 2 entries (allowed: an array of tables, [[head.ts]], at most 1)" in _message(
        lambda: table.tables("ts", max_count=1)
    )


def test_done_rejects_keys_no_getter_asked_for_and_fast_values_are_named() -> None:
    table = _table({"kx": 1.0, "typo": 2})
    table.number("kx")
    assert _message(table.done) == "case.toml: head.typo: unknown key (allowed: kx)"
    fast = _table({"kx": -1.0}, fast={"head": {"kx": -1.0}})
    assert "case.toml: fast.head.kx: -1 is out of range" in _message(
        lambda: fast.number("kx", lo=0)
    )
