"""The documentation site builds with warnings as errors, its generated pages whole."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from headsim.errors import EXIT_MEANINGS, ExitCode
from headsim.scenario.key_reference import DESCRIPTIONS

ROOT = Path(__file__).resolve().parents[1]


def _build(site: Path, docs: Path | None = None) -> subprocess.CompletedProcess[str]:
    config = ROOT / "mkdocs.yml"
    if docs is not None:  # the same configuration over a changed copy of the pages
        text = config.read_text().replace("docs_dir: docs", f"docs_dir: {docs}")
        config = ROOT / f".mkdocs-test-{os.getpid()}.yml"
        config.write_text(text)
    try:
        return subprocess.run(
            [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
            cwd=ROOT, capture_output=True, text=True, timeout=300, check=False,
            env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        )  # fmt: skip
    finally:
        if docs is not None:
            config.unlink()


def test_the_site_builds_strictly_with_every_generated_page(tmp_path: Path) -> None:
    done = _build(tmp_path / "site")
    assert done.returncode == 0, done.stderr
    keys = (tmp_path / "site" / "reference" / "scenario-keys" / "index.html").read_text()
    for path in DESCRIPTIONS:
        assert f"<code>{path}</code>" in keys, path
    cli = (tmp_path / "site" / "reference" / "command-line" / "index.html").read_text()
    assert "headsim run" in cli and "--rrd" in cli
    codes = (tmp_path / "site" / "reference" / "exit-codes" / "index.html").read_text()
    assert all(f"<td>{int(c)}</td>" in codes for c in ExitCode)
    api = (tmp_path / "site" / "reference" / "api" / "index.html").read_text()
    assert "load_scenario" in api and "HeadSim" in api


def test_a_broken_link_fails_the_build(tmp_path: Path) -> None:
    docs = tmp_path / "docs"
    subprocess.run(["cp", "-r", str(ROOT / "docs"), str(docs)], check=True)
    page = docs / "python.md"
    page.write_text(page.read_text() + "\n[gone](no-such-page.md)\n")
    done = _build(tmp_path / "site", docs)
    assert done.returncode == 1
    assert re.search(r"python\.md.*no-such-page\.md", done.stderr), done.stderr


def test_every_exit_code_has_its_meaning() -> None:
    assert list(EXIT_MEANINGS) == list(ExitCode)
