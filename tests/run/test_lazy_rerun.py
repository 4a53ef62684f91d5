"""Rerun (a third of a second to import) loads only when a run records."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

#: What ``headsim run`` without --rrd/--connect/--serve imports: the command line, the runner,
#: every procedure (discovered, as the first lookup does) and every shipped scenario, loaded.
UNRECORDED_RUN_IMPORTS = """
import headsim, headsim.cli, headsim.cli.parser, headsim.cli.scenarios, headsim.cli.studies
import headsim.procedures, headsim.runs.runner, headsim.runs.serialise, headsim.runs.summary
headsim.procedures.discover()
from headsim.runs.rerun_cli import recording_target
from headsim.scenario.loading import load_scenario, scenario_files
for path in scenario_files():
    load_scenario(path.stem, fast=True)
"""


def loaded_rerun(code: str, cwd: Path) -> list[str]:
    """The Rerun modules a plain ``python -c code`` (no pytest, no conftest) has loaded."""
    report = "\nimport sys; print(sorted(m for m in sys.modules if m.split('.')[0] == 'rerun'))"
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    done = subprocess.run(
        [sys.executable, "-c", code + report],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    return ast.literal_eval(done.stdout.strip().splitlines()[-1])


@pytest.mark.fast
def test_import_headsim_does_not_import_rerun(tmp_path: Path) -> None:
    assert loaded_rerun("import headsim", tmp_path) == []


@pytest.mark.fast
def test_an_unrecorded_runs_imports_and_scenarios_do_not_import_rerun(tmp_path: Path) -> None:
    assert loaded_rerun(UNRECORDED_RUN_IMPORTS, tmp_path) == []
    # The check can fail: the recorder's module brings Rerun with it.
    assert "rerun" in loaded_rerun("import headsim.runs.recording", tmp_path)


def test_a_run_imports_rerun_only_when_it_records(tmp_path: Path) -> None:
    run = "from headsim.cli import main\nassert main(['run', 'quickstart', '--fast', '--no-progress', '--out', 'out'{}]) == 0"
    assert loaded_rerun(run.format(""), tmp_path) == []
    assert "rerun" in loaded_rerun(run.format(", '--rrd', 'run.rrd'"), tmp_path)
