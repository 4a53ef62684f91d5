"""Every ``python`` block on the documentation's pages runs: a page's blocks in order, in
one namespace, in a fresh interpreter, in an empty folder, so the examples cannot rot."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from headsim.cli import main

DOCS = Path(__file__).resolve().parents[1] / "docs"
#: A fenced block opened by ```python (nothing else on the line) up to its closing fence.
BLOCK = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.MULTILINE | re.DOTALL)
#: Runs a page's blocks, each compiled under its page and first line for tracebacks.
RUNNER = """
import re, sys
from pathlib import Path
page = Path(sys.argv[1])
text = page.read_text()
namespace = {"__name__": "__main__"}
for match in re.finditer(sys.argv[2], text, re.MULTILINE | re.DOTALL):
    line = text.count("\\n", 0, match.start(1)) + 1
    code = compile("\\n" * (line - 1) + match.group(1), str(page), "exec")
    exec(code, namespace)
"""


def blocks(page: Path) -> list[str]:
    return BLOCK.findall(page.read_text())


PAGES = sorted(p for p in DOCS.rglob("*.md") if blocks(p))
#: What a page's examples may read that the quick start writes (made before they run).
QUICKSTART_RECORDING = "out/quickstart/recording.rrd"


def test_the_python_page_has_examples() -> None:
    assert DOCS / "python.md" in PAGES
    assert len(blocks(DOCS / "python.md")) >= 5


def test_the_block_pattern_finds_only_python_blocks(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("```python\nprint(1)\n```\n\n```text\nnot run\n```\n\n```python\nx = 2\n```\n")
    assert blocks(page) == ["print(1)\n", "x = 2\n"]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(DOCS)))
def test_every_python_example_runs(page: Path, tmp_path: Path) -> None:
    if QUICKSTART_RECORDING in page.read_text():
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
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    done = subprocess.run(
        [sys.executable, "-c", RUNNER, str(page), BLOCK.pattern],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, f"{page.name}: an example failed:\n{done.stderr[-4000:]}"
