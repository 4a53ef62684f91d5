"""The study's command line (``headsim study``; ``python -m headsim.studies.study`` its
deprecated alias): clear errors for unknown names, and a sweep with progress and files."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from headsim import cli
from headsim.studies import study
from headsim.studies.catalogue import sweep_experiment
from headsim.studies.methods import StudyConfig
from headsim.studies.target_errors import measure_methods

CONFIG = StudyConfig.quick()


def test_unknown_names_are_clear_errors(calibrations) -> None:
    with pytest.raises(ValueError, match="unknown sweep 'nope'; allowed: depth, focal"):
        sweep_experiment("nope", CONFIG)
    with pytest.raises(ValueError, match="unknown methods"):
        measure_methods(calibrations.settings, calibrations, [[0, 0, 1]], ("laser",))
    # The deprecated alias is the headsim parser's command, and says so.
    alias = subprocess.run(
        [sys.executable, "-m", "headsim.studies.study", "--sweep", "nope", "--out", "unused"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert alias.returncode == 2
    assert study.ALIAS_NOTE in alias.stderr
    assert "headsim study: error: argument --sweep: invalid choice: 'nope'" in alias.stderr


def test_the_command_runs_a_sweep_with_progress_and_files(tmp_path, capsys) -> None:
    assert cli.main(["study", "--sweep", "depth", "--fast", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "calibrating every method on paper" in captured.err
    assert "[2/2] paper: 1.5 (kept)" in captured.err
    assert "== depth" in captured.out and "stereo" in captured.out
    index = json.loads((tmp_path / "results.json").read_text())
    assert set(index["experiments"]) == {"depth"}
    for name in index["experiments"]["depth"]["files"].values():
        assert (tmp_path / name).stat().st_size > 0
