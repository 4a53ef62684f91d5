"""The documentation site builds with warnings as errors, its generated pages whole."""

from __future__ import annotations

import html
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from headsim import __version__
from headsim.errors import ExitCode
from headsim.scenario.key_reference import descriptions
from headsim.scenario.loading import scenario_files
from headsim.sim.heads import REGISTRY

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


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The site, built once for the tests that read it."""
    site = tmp_path_factory.mktemp("docs") / "site"
    done = _build(site)
    assert done.returncode == 0, done.stderr
    return site


def test_the_site_builds_strictly_with_every_generated_page(site: Path) -> None:
    keys = (site / "reference" / "scenario-keys.html").read_text()
    for path in descriptions():
        assert f"<code>{path}</code>" in keys, path
    cli = (site / "reference" / "command-line.html").read_text()
    assert "headsim run" in cli and "--rrd" in cli
    codes = (site / "reference" / "exit-codes.html").read_text()
    assert all(f"<td>{int(c)}</td>" in codes for c in ExitCode)
    api = (site / "reference" / "api.html").read_text()
    assert "load_scenario" in api and "HeadSim" in api


def test_the_api_page_renders_roles_types_and_each_entry_once(site: Path) -> None:
    api = (site / "reference" / "api.html").read_text()
    text = html.unescape(re.sub(r"<[^>]+>", "", api))
    raw = re.findall(r":(?:class|func|meth|mod|data|attr|exc|obj):`?", text)
    assert not raw, f"{len(raw)} raw Sphinx roles, e.g. {raw[:3]}"
    assert not re.search(r"\w::\s", text), "a reST literal-block marker (::) shown raw"
    # A role naming an object on the page is a link to it (run's docstring names load_scenario).
    assert 'href="#headsim.runs.library.load_scenario"' in api
    # Signatures carry their annotations: load_scenario's ``fast: bool``.
    entry = api.split('id="headsim.runs.library.load_scenario"', 1)[1]
    signature = entry.split("doc-signature", 1)[1].split("</pre>", 1)[0]
    assert re.search(r"fast.*?:.*?bool", html.unescape(re.sub(r"<[^>]+>", "", signature)))
    # Each module's own entries (not methods: two classes may each have a ``describe``).
    modules = set(re.findall(r'<h2 id="(headsim[\w.]*)" class="doc doc-heading">', api))
    headings = re.findall(r'<h3 id="(headsim[\w.]*)" class="doc doc-heading">', api)
    names = [h.rsplit(".", 1)[-1] for h in headings if h.rsplit(".", 1)[0] in modules]
    assert len(modules) >= 8 and len(names) > 20
    assert len(set(names)) == len(names), sorted(n for n in names if names.count(n) > 1)


def test_the_site_works_opened_from_disk(site: Path) -> None:
    """Every page link of every page names a file of the site (no folder, which a
    browser shows as a listing when the site is opened from disk)."""
    # 404.html is a server's page (its links are absolute, from the site's root).
    pages = sorted(p for p in site.rglob("*.html") if p.name != "404.html")
    assert site / "index.html" in pages and len(pages) > 25
    checked = 0
    for page in pages:
        for href in re.findall(r'href="([^"]+)"', page.read_text()):
            target = href.split("#", 1)[0].split("?", 1)[0]
            if not target or re.match(r"[a-z]+:", target):
                continue  # an anchor on the page, or another site
            path = (page.parent / target).resolve()
            assert path.is_file(), f"{page.relative_to(site)}: {href} is not a file"
            checked += 1
    assert checked > 25 * 20  # the navigation of every page, at least
    index = (site / "index.html").read_text()
    for linked in ("how-to/own-head.html", "how-to/live-head.html", "reference/api.html"):
        assert f'href="{linked}"' in index, linked


def test_the_home_page_gives_version_install_and_citation(site: Path) -> None:
    index = (site / "index.html").read_text()
    text = html.unescape(re.sub(r"<[^>]+>", "", index))
    assert f"Version {__version__}" in text
    assert "pip install ." in text and "headsim run quickstart" in text
    assert "A New Active Visual System for Humanoid Robots" in text and "CITATION.cff" in text
    assert "generated:" not in index  # every generated block was filled


def test_the_scenario_table_lists_every_shipped_scenario(site: Path) -> None:
    page = (site / "how-to" / "write-a-scenario.html").read_text()
    table = page.split("<table>", 1)[1].split("</table>", 1)[0]
    names = re.findall(r"<tr>\s*<td><code>(\w+)</code></td>", table)
    assert names == [path.stem for path in scenario_files()]
    assert len(names) >= 14


@pytest.mark.parametrize(
    ("page", "section"),
    [("how-to/own-head.html", "a-shipped-head"), ("concepts/model.html", "heads")],
)
def test_the_head_tables_list_every_shipped_head(site: Path, page: str, section: str) -> None:
    """Run your own head's and The model's generated tables: one row per registered head."""
    after = (site / page).read_text().split(f'<h2 id="{section}">', 1)[1]
    table = after.split("<table>", 1)[1].split("</table>", 1)[0]
    assert re.findall(r"<tr>\s*<td><code>(\w+)</code>", table) == list(REGISTRY)


def test_the_citation_file_cites_the_software_and_the_paper() -> None:
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0"
    assert cff["type"] == "software" and cff["license"] == "Apache-2.0"
    assert str(cff["version"]) == __version__
    assert cff["message"] and cff["title"].startswith("headsim")
    assert all("name" in a or "family-names" in a for a in cff["authors"])
    (paper,) = cff["references"]
    assert paper["type"] == "article"
    assert paper["title"] == "A New Active Visual System for Humanoid Robots"
    assert [a["family-names"] for a in paper["authors"]] == ["Xu", "Li", "Tan", "Shen"]
    assert "Part B" in paper["journal"]
    assert re.fullmatch(r"\d{4}-\d{3}[\dX]", str(paper["issn"]))
    allowed = {  # CFF 1.2.0's keys of the root and of a reference, as used here
        "cff-version", "message", "type", "title", "abstract", "authors", "version",
        "license", "keywords", "references", "journal", "issn",
    }  # fmt: skip
    assert set(cff) <= allowed and set(paper) <= allowed


def test_a_broken_link_fails_the_build(tmp_path: Path) -> None:
    docs = tmp_path / "docs"
    subprocess.run(["cp", "-r", str(ROOT / "docs"), str(docs)], check=True)
    page = docs / "python.md"
    page.write_text(page.read_text() + "\n[gone](no-such-page.md)\n")
    done = _build(tmp_path / "site", docs)
    assert done.returncode == 1
    assert re.search(r"python\.md.*no-such-page\.md", done.stderr), done.stderr


def test_the_screenshot_tool_refuses_without_chromium_and_writes_nothing(tmp_path: Path) -> None:
    png = tmp_path / "recording.png"
    done = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "recording_screenshot.py"), "--out",
         str(tmp_path / "out"), "--png", str(png), "--chromium", str(tmp_path / "no-chromium")],
        cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert done.returncode == 3, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Chromium is not installed" in lines[0], done.stderr
    assert not png.exists() and not (tmp_path / "out").exists()
