"""A file's text reaches the terminal escaped: a control character in a scenario's
description, name, target name or key shows as ``\\u001b`` and never acts on it."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

from headsim.cli import main
from headsim.errors import printable

#: Any control character but the newline (C0, DEL, C1), as it would reach the terminal raw.
RAW = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")

HOSTILE = r"""
description = "clears the screen \u001b[2J and rings \u0007"

[experiment]
procedure = "model2"

[[scene.targets]]
name = "bell\u0007"
position_head_m = [0.02, 0.01, 0.6]
"""


def test_printable_escapes_every_control_character_but_the_newline() -> None:
    assert printable("a\x1b[2Jb\nc\td\x7f\x9b\u202e") == r"a\u001b[2Jb" + "\n" + (
        r"c\u0009d\u007f\u009b\u202e"
    )
    assert printable("plain text, ünïcode, 1.5 mm") == "plain text, ünïcode, 1.5 mm"


def test_list_shows_a_description_escaped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "hostile.toml").write_text(HOSTILE)
    (tmp_path / "bad\x1b[2J.toml").write_text(HOSTILE.replace("model2", r"\u001b[31m"))
    assert main(["list", "--dir", str(tmp_path)]) == 2  # the bad one is INVALID
    out, err = capsys.readouterr()
    assert not RAW.search(out + err)
    assert r"clears the screen \u001b[2J and rings \u0007" in out
    assert r"bad\u001b[2J" in out and r"\x1b[31m" in out  # the value as repr escapes it


def test_run_shows_the_summary_escaped(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "hostile.toml"
    path.write_text(HOSTILE)
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 0  # progress too
    out, err = capsys.readouterr()
    assert not RAW.search(out + err)
    assert r"bell\u0007" in out and r"\u001b[2J" in out
    # The files keep the text as the scenario gave it.
    assert "\x1b[2J" in (tmp_path / "out" / "summary.txt").read_text()


def test_an_error_shows_a_file_key_escaped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "hostile.toml"
    path.write_text(HOSTILE + '\n[cam1]\n"\\u001b]0;owned\\u0007" = 1\n')
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    out, err = capsys.readouterr()
    assert not RAW.search(out + err)
    assert r"cam1.\u001b]0;owned\u0007: unknown key" in err and err.count("\n") == 1


def test_progress_lines_show_a_target_name_escaped() -> None:
    from headsim.runs.progress import Counter

    stream = io.StringIO()
    counter = Counter(
        2, unit="fixations", stream=stream, terminal=False, interval_s=0.0, notes_in_lines=True
    )
    counter.phase("measurement\x1b[2J")
    counter.update(1, "bell\x07")
    counter.close()
    text = stream.getvalue()
    assert not RAW.search(text)
    assert r"measurement\u001b[2J: 1/2 fixations bell\u0007" in text
