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
