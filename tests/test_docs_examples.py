"""Every example on the documentation's pages runs as printed, or says why it is not run.

A fenced ``python``, ``toml``, ``xml`` or ``bash`` block is an example. ``python`` blocks
run unless marked: a page's blocks in order, as one script, in a fresh interpreter, in an
empty folder (the page's folder). Any other example carries a marker, an HTML comment
on the line before its fence:

- ``<!-- example: file NAME -->``: written as NAME in the page's folder (an MJCF head);
- ``<!-- example: scenario NAME -->``: written as NAME and loaded as a scenario;
- ``<!-- example: sweep NAME -->``: written as NAME and loaded as a sweep file;
- ``<!-- example: run -->``: a ``bash`` block run with ``bash -e`` in the page's folder,
  the installed ``headsim`` first on the PATH, after the page's files and scripts;
- ``<!-- example: not run: REASON -->``: shown, not run, for the reason given.

``<!-- examples: not run (LANG): REASON -->`` anywhere on a page marks its unmarked
blocks of LANG (the commands of the results page, which tools/readme_figures.py runs).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from headsim.cli import main
from headsim.scenario.loading import load_scenario
from headsim.studies.sweep_spec import load_sweep

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: The languages of a fenced block that make it an example.
EXAMPLE_LANGUAGES = ("python", "toml", "xml", "bash")
#: A fenced block, possibly indented (in a list), up to its closing fence.
FENCE = re.compile(
    r"^(?P<indent>[ \t]*)```(?P<lang>[A-Za-z]*)[ \t]*\n(?P<body>.*?)^(?P=indent)```[ \t]*$",
    re.MULTILINE | re.DOTALL,
)
MARK = re.compile(r"^\s*<!-- example: (?P<what>.+?) -->\s*$")
PAGE_MARK = re.compile(r"<!-- examples: not run \((?P<lang>[a-z]+)\): (?P<reason>.+?) -->")
KINDS = ("file", "scenario", "sweep", "run", "not run")
#: What a page's examples may read that the quick start writes (made before they run).
QUICKSTART_RECORDING = "out/quickstart/recording.rrd"


@dataclass(frozen=True)
class Example:
    """One fenced example of a page: what is done with it."""

    lang: str
    body: str
    line: int  # of the block's first line of code, 1-based
    kind: str  # one of KINDS, or "" when unmarked
    arg: str  # the file name, the reason, or ""


def examples(page: Path) -> list[Example]:
    """The page's examples, with the marker each carries."""
    text = page.read_text()
    page_marks = {m["lang"]: m["reason"] for m in PAGE_MARK.finditer(text)}
    found = []
    for match in FENCE.finditer(text):
        lang = match["lang"]
        if lang not in EXAMPLE_LANGUAGES:
            continue
        before = text[: match.start()].rstrip("\n").rsplit("\n", 1)[-1]
        kind, arg = "", ""
        if mark := MARK.match(before):
            what = mark["what"]
            kind = next((k for k in KINDS if re.match(rf"{k}(:| |$)", what)), what)
            arg = what[len(kind) :].lstrip(": ").strip() if kind in KINDS else ""
        elif lang in page_marks:
            kind, arg = "not run", page_marks[lang]
        body = "\n".join(line.removeprefix(match["indent"]) for line in match["body"].split("\n"))
        line = text.count("\n", 0, match.start("body")) + 1
        found.append(Example(lang, body, line, kind, arg))
    return found


def problems(example: Example) -> str | None:
    """Why an example is neither run nor properly marked; None when it is."""
    if example.kind == "":
        return None if example.lang == "python" else "no marker (<!-- example: ... -->)"
    if example.kind not in KINDS:
        return f"unknown marker {example.kind!r} (allowed: {', '.join(KINDS)})"
    if example.kind == "not run":
        return None if example.arg else "'not run' without a reason"
    if example.kind == "run":
        return None if example.lang == "bash" else "'run' marks a bash block"
    if not re.fullmatch(r"[\w.-]+", example.arg):
        return f"{example.kind} needs a plain file name, got {example.arg!r}"
    return None


def runnable(example: Example) -> bool:
    return example.kind in ("", "file", "scenario", "sweep", "run")


def script(page: Path, chosen: list[Example]) -> str:
    """The page's python blocks as one script, each at its own line numbers (tracebacks
    name the page's lines)."""
    lines = [""] * (page.read_text().count("\n") + 1)
    for example in chosen:
        for offset, code in enumerate(example.body.split("\n")):
            lines[example.line - 1 + offset] = code
    return "\n".join(lines)


PAGES = sorted(p for p in DOCS.rglob("*.md") if examples(p))
RUN_PAGES = [p for p in PAGES if any(runnable(e) for e in examples(p))]


def _id(page: Path) -> str:
    return str(page.relative_to(DOCS))


def test_the_python_page_has_examples() -> None:
    assert DOCS / "python.md" in PAGES
    assert sum(e.lang == "python" and runnable(e) for e in examples(DOCS / "python.md")) >= 5


def test_the_markers_are_read(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text(
        "<!-- examples: not run (bash): long -->\n"
        "```python\nprint(1)\n```\n\n```text\nnot an example\n```\n\n"
        "<!-- example: file head.xml -->\n```xml\n<mujoco/>\n```\n"
        "1. A step:\n\n    <!-- example: run -->\n    ```bash\n    headsim list\n    ```\n"
        "<!-- example: not run: needs a GPU -->\n```python\nx = 2\n```\n"
        "```bash\nheadsim bench\n```\n```toml\na = 1\n```\n"
    )
    got = [(e.lang, e.kind, e.arg, e.body) for e in examples(page)]
    assert got == [
        ("python", "", "", "print(1)\n"),
        ("xml", "file", "head.xml", "<mujoco/>\n"),
        ("bash", "run", "", "headsim list\n"),
        ("python", "not run", "needs a GPU", "x = 2\n"),
        ("bash", "not run", "long", "headsim bench\n"),
        ("toml", "", "", "a = 1\n"),
    ]
    assert [problems(e) for e in examples(page)][-1] == "no marker (<!-- example: ... -->)"
    assert script(page, examples(page)[:1]).split("\n")[2] == "print(1)"


def test_every_example_is_run_or_marked_with_a_reason() -> None:
    bad = [
        f"{_id(page)}:{e.line}: {problem}"
        for page in PAGES
        for e in examples(page)
        if (problem := problems(e))
    ]
    assert not bad, "\n".join(bad)
    counts = {"run": 0, "not run": 0}
    for page in PAGES:
        for e in examples(page):
            counts["run" if runnable(e) else "not run"] += 1
    # The pages that teach a file format run it: the own head (MJCF, scenario, command).
    own_head = {(e.lang, e.kind) for e in examples(DOCS / "how-to" / "own-head.md")}
    assert {("xml", "file"), ("toml", "scenario"), ("bash", "run")} <= own_head
    assert counts["run"] > counts["not run"] / 2, counts


@pytest.mark.parametrize("page", RUN_PAGES, ids=_id)
def test_every_example_runs_as_printed(page: Path, tmp_path: Path) -> None:
    chosen = [e for e in examples(page) if runnable(e)]
    for e in chosen:
        if e.kind in ("file", "scenario", "sweep"):
            (tmp_path / e.arg).write_text(e.body)
    for e in chosen:  # checked as the loaders check them, before anything runs
        if e.kind == "scenario":
            load_scenario(tmp_path / e.arg)
        elif e.kind == "sweep":
            load_sweep(tmp_path / e.arg)
    env = {
        **os.environ,
        "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl"),
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
    }
    python = [e for e in chosen if e.lang == "python"]
    if python:
        if QUICKSTART_RECORDING in page.read_text():
            out = tmp_path / "out" / "quickstart"
            args = ["run", "quickstart", "--fast", "--out", str(out)]
            args += ["--rrd", str(out / "recording.rrd"), "--no-progress", "--quiet"]
            assert main(args) == 0
        runner = tmp_path / f"{page.stem}_examples.py"
        runner.write_text(script(page, python))
        done = subprocess.run(
            [sys.executable, runner.name],
            cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert done.returncode == 0, f"{_id(page)}: an example failed:\n{done.stderr[-4000:]}"
    for e in (e for e in chosen if e.kind == "run"):
        done = subprocess.run(
            ["bash", "-e", "-o", "pipefail", "-c", e.body],
            cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert done.returncode == 0, (
            f"{_id(page)}:{e.line}: {e.body!r} exited {done.returncode}:\n{done.stderr[-4000:]}"
        )
        if "headsim run my_head.toml" in e.body:  # the own head's printed result
            assert "OK: 2 measurements, none failed" in done.stdout, done.stdout
