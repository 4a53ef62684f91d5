"""The documentation's figures are today's: the cheap blocks regenerated from runs must match."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TOOL = ROOT / "tools" / "readme_figures.py"


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(TOOL), *args], capture_output=True, text=True, cwd=ROOT, timeout=300
    )


def _copy(tmp_path: Path) -> Path:
    """The README and the pages, where the tool may change them."""
    shutil.copy(ROOT / "README.md", tmp_path / "README.md")
    shutil.copytree(ROOT / "docs", tmp_path / "docs")
    return tmp_path


def test_the_cheap_figure_blocks_match_a_run_of_todays_code() -> None:
    done = _run("--cheap")
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_stale_figure_is_caught_and_named_on_its_page(tmp_path: Path) -> None:
    root = _copy(tmp_path)
    page = root / "docs" / "results.md"
    text = page.read_text()
    start = text.index("<!-- figures:quickstart -->")
    end = text.index("<!-- /figures:quickstart -->")
    page.write_text(text[:start] + "<!-- figures:quickstart -->\n0.100 % of depth\n" + text[end:])
    done = _run("--only", "quickstart", "--root", str(root))
    assert done.returncode == 1
    assert "-0.100 % of depth" in done.stdout and "docs/results.md quickstart" in done.stdout
    assert _run("--only", "quickstart", "--root", str(root), "--write").returncode == 0
    assert page.read_text() == text


def test_a_block_without_a_generator_or_on_two_pages_is_refused(tmp_path: Path) -> None:
    root = _copy(tmp_path)
    page = root / "docs" / "python.md"
    page.write_text(page.read_text() + "\n<!-- figures:nothing -->\n<!-- /figures:nothing -->\n")
    done = _run("--cheap", "--root", str(root))
    assert done.returncode == 2 and "['nothing']" in done.stderr
    page.write_text(page.read_text() + "\n<!-- figures:gym -->\n<!-- /figures:gym -->\n")
    done = _run("--cheap", "--root", str(root))
    assert done.returncode == 2 and "two pages: ['gym']" in done.stderr


def test_a_timed_block_is_checked_by_its_words_and_every_other_by_its_numbers_too() -> None:
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import readme_figures as figures
    finally:
        sys.path.remove(str(ROOT / "tools"))
    assert figures.GENERATORS["speed"].timed and not figures.GENERATORS["quickstart"].timed
    ours, later = "took 71 renders' time; reproduce 484.5", "took 90 renders' time; reproduce 350.0"
    assert figures._compared("speed", ours) == figures._compared("speed", later)
    assert figures._compared("speed", ours) != figures._compared("speed", "took 71 frames' time")
    assert figures._compared("quickstart", "0.111 %") != figures._compared("quickstart", "0.112 %")
