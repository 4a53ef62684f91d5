"""Parsing a scenario file (scenario/toml_file.py): every failure one line naming the line."""

from __future__ import annotations

from pathlib import Path

import pytest

from headsim.scenario.tables import ScenarioError
from headsim.scenario.toml_file import MAX_NESTING, deep_line, read_toml, text_or_empty


def _refused(path: Path) -> str:
    with pytest.raises(ScenarioError) as caught:
        read_toml(path)
    text = str(caught.value)
    assert "\n" not in text and text.startswith(f"{path}: ")
    return text


def test_a_file_parses_with_or_without_a_byte_order_mark(tmp_path: Path) -> None:
    path = tmp_path / "ok.toml"
    path.write_bytes(b'\xef\xbb\xbfseed = 3\n[head]\npreset = "paper"\n')
    assert read_toml(path) == {"seed": 3, "head": {"preset": "paper"}}
    assert text_or_empty(path).startswith("seed = 3")
    assert text_or_empty(tmp_path / "absent.toml") == ""


def test_nesting_is_counted_outside_strings_and_comments() -> None:
    deep = "[" * (MAX_NESTING + 1)
    assert deep_line("a = 1\nb = " + deep) == " at line 2"
    assert deep_line("a = " + "[" * MAX_NESTING + "]" * MAX_NESTING) == ""
    assert deep_line(f"a = \"{deep}\"\nb = '{deep}'\n# {deep}\n") == ""
    assert deep_line('a = "q\\"' + deep + '"') == ""  # an escaped quote stays in the string


def test_bad_files_are_refused_naming_the_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_bytes(b"a = 1\nb = '\xff'\n")
    assert "line 2: not UTF-8 text" in _refused(path)
    path.write_text("a = 1\nb = " + "{ c = " * 60 + "1" + " }" * 60 + "\n")
    assert "nested too deeply at line 2 (allowed: at most 50 levels)" in _refused(path)
    path.write_text("a = 1\nb = [1,\n")
    assert "not valid TOML" in _refused(path)
    path.write_text("a = 1\n\nb = " + "7" * 4400 + "\n")
    assert "line 3: a number with too many digits" in _refused(path)
    assert "cannot be read" in _refused(tmp_path / "absent.toml")
