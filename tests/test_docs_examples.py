"""Every Python example on the documentation's pages runs, each in a fresh interpreter."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from headsim.cli import main

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
EXAMPLES = [
    pytest.param(page, k, code, id=f"{page.relative_to(ROOT / 'docs')}:{k}")
    for page in sorted((ROOT / "docs").rglob("*.md"))
    for k, code in enumerate(FENCE.findall(page.read_text()))
]


def test_the_pages_hold_examples() -> None:
    assert len(EXAMPLES) >= 3


@pytest.mark.parametrize(("page", "index", "code"), EXAMPLES)
def test_every_example_runs(page: Path, index: int, code: str, tmp_path: Path) -> None:
    if "out/quickstart/recording.rrd" in code:  # the quick start's recording, made here
        out = tmp_path / "out" / "quickstart"
        args = [
            "run",
            "quickstart",
            "--fast",
            "--out",
            str(out),
            "--rrd",
            str(out / "recording.rrd"),
        ]
        assert main([*args, "--no-progress", "--quiet"]) == 0
    done = subprocess.run(
        [sys.executable, "-W", "error", "-c", code],
        cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False,
        env={**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")},
    )  # fmt: skip
    assert done.returncode == 0, f"{page.name} example {index}:\n{done.stderr[-3000:]}"
