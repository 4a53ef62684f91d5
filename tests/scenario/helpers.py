"""Scenario files written for tests: the smallest valid one, and a writer."""

from __future__ import annotations

import textwrap
from pathlib import Path

MINIMAL = """
description = "a test"

[experiment]
procedure = "model2"

[[scene.targets]]
position_head_m = [0.02, 0.01, 0.6]
"""


def write_scenario(tmp_path: Path, text: str, name: str = "bad.toml") -> Path:
    """``text`` (dedented) written to ``tmp_path / name``."""
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path
