"""The study commands (cli/studies.py): outputs refused before any work, with exit 2, and
folders they made for nothing removed."""

from __future__ import annotations

from pathlib import Path

import pytest

from headsim.cli import main

SWEEP = Path(__file__).resolve().parents[2] / "sweeps" / "focal.toml"


@pytest.fixture
def afile(tmp_path: Path) -> Path:
    path = tmp_path / "file"
    path.write_text("x")
    return path


def test_study_refuses_an_output_that_is_a_file(afile: Path, capsys) -> None:
    assert main(["study", "--experiment", "budget", "--fast", "--out", str(afile)]) == 2
    assert f"--out: {afile} exists and is not a directory" in capsys.readouterr().err
    assert afile.read_text() == "x"


def test_bench_refuses_its_outputs_and_removes_the_folders_it_made(tmp_path: Path, capsys) -> None:
    assert main(["bench", "--json", str(tmp_path)]) == 2
    assert f"--json: {tmp_path} is a directory (allowed: a file path)" in capsys.readouterr().err
    made = tmp_path / "new" / "deeper"
    code = main(
        ["bench", "--json", str(made / "b.json"), "--update-baseline", "--baseline", str(tmp_path)]
    )
    assert code == 2 and "--baseline" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()


def test_sweep_refuses_a_missing_file_and_an_output_that_is_a_file(
    tmp_path: Path, afile: Path, capsys
) -> None:
    assert main(["sweep", str(tmp_path / "none.toml"), "--out", str(tmp_path / "sw")]) == 2
    assert "none.toml: no such sweep file" in capsys.readouterr().err
    assert main(["sweep", str(SWEEP), "--out", str(afile)]) == 2
    captured = capsys.readouterr()
    assert "exists and is not a directory" in captured.err
    assert "jobs of" not in captured.out  # refused before anything is printed or run
    assert not (tmp_path / "sw").exists()
