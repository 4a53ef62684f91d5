"""The README's figures are today's: the cheap blocks regenerated from runs must match."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TOOL = ROOT / "tools" / "readme_figures.py"


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(TOOL), *args], capture_output=True, text=True, cwd=ROOT, timeout=300
    )


def test_the_readmes_cheap_figure_blocks_match_a_run_of_todays_code() -> None:
    done = _run("--cheap")
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_stale_figure_is_caught_and_named(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    text = (ROOT / "README.md").read_text()
    start = text.index("<!-- figures:quickstart -->")
    end = text.index("<!-- /figures:quickstart -->")
    stale = text[:start] + "<!-- figures:quickstart -->\n0.100 % of depth\n" + text[end:]
    readme.write_text(stale)
    done = _run("--only", "quickstart", "--readme", str(readme))
    assert done.returncode == 1
    assert "-0.100 % of depth" in done.stdout and "README quickstart" in done.stdout
    assert _run("--only", "quickstart", "--readme", str(readme), "--write").returncode == 0
    assert readme.read_text() == text


def test_a_block_without_a_generator_is_refused(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text(
        (ROOT / "README.md").read_text() + "\n<!-- figures:nothing -->\n<!-- /figures:nothing -->\n"
    )
    done = _run("--cheap", "--readme", str(readme))
    assert done.returncode == 2 and "['nothing']" in done.stderr
