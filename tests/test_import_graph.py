"""The package's layers hold: no import circle, no upward import, no module over about 800 lines
(modules are sized by concern)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_no_circle_no_upward_import_no_module_over_800_lines() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "import_graph.py"), str(ROOT)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert "circles: 0" in result.stdout, result.stdout
    assert "upward imports" in result.stdout and "): 0" in result.stdout, result.stdout
    assert result.returncode == 0, result.stdout


def _check(root: Path) -> str:
    result = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "import_graph.py"), str(root)],
        capture_output=True,
        text=True,
        check=False,
    )
    return result.stdout


def test_a_circle_through_type_checking_or_importlib_is_counted(tmp_path: Path) -> None:
    package = tmp_path / "headsim"
    (package / "scenario").mkdir(parents=True)
    (package / "runs").mkdir()
    (package / "plugins").mkdir()
    for folder in (package, package / "scenario", package / "runs", package / "plugins"):
        (folder / "__init__.py").write_text("")
    (package / "scenario" / "spec.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from headsim.runs.hub import Hub\n"
    )
    (package / "runs" / "hub.py").write_text("from headsim.scenario.spec import Spec\n")
    (package / "runs" / "look.py").write_text(
        'import importlib\nPLUGINS = "headsim.plugins"\n\n\ndef load(name):\n'
        '    importlib.import_module(PLUGINS + "." + name)\n'
    )
    (package / "plugins" / "one.py").write_text("from headsim.runs.look import load\n")
    out = _check(tmp_path)
    assert "circles: 2" in out, out
    assert "headsim.runs.hub <-> headsim.scenario.spec" in out, out
    assert "headsim.plugins.one <-> headsim.runs.look" in out, out
    assert "headsim.scenario.spec -> headsim.runs.hub" in out, out  # upward, under TYPE_CHECKING
