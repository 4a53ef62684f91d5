"""The repository is self-contained: no file refers to anything outside it.

A reader has only the repository (and the paper's citation), so every file the
repository's files cite must be in it.  Each file git knows (tracked, or new and
not ignored) is read as text (binary files are passed over) and must not hold:

- the design folder beside the checkout (``..`` then ``shared``), which a clone does not have;
- ``equations.md`` other than as ``docs/equations.md``, the project's own
  document of frames, signs and equations (which must exist);
- a machine path used as a reference: an absolute path into someone's home or a
  build machine's tree (``/home/``, ``/Users/``, ``/root/``, ``/work/``, ``/mnt/``,
  ``/srv/``, ``C:\\Users\\``);
- a markdown link whose relative target climbs out of the repository.

Allowed, because they name no content of another machine: scratch folders in
examples (``/tmp/``, ``~/``), system locations a program uses (``/usr/bin/env``,
``/dev/null``, ``/etc/``, ``/proc/``), made-up paths in error messages under test
(``/data/r.json``), and the same words inside a URL (``https://host/home/``: a
machine path starts a word, it does not follow a host or another path).  This
file itself is left out: it names what it looks for.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
#: What is looked for, each with what it is (the message when it is found).
PATTERNS = {
    "a folder beside the checkout": re.compile(r"\.\./shared\b"),
    "equations.md not as docs/equations.md": re.compile(r"(?<!(?<![\w./-])docs/)equations\.md"),
    "a machine path": re.compile(
        r"(?<![\w.:/~-])(?:/home/|/Users/|/root/|/work/|/mnt/|/srv/|[A-Za-z]:\\+Users\\)"
    ),
}
#: A markdown link's target: [text](target).
MARKDOWN_LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def _files() -> list[Path]:
    """Every file git knows in the repository: tracked, or new and not ignored."""
    listed = subprocess.run(
        ["git", "-C", str(REPO), "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        capture_output=True,
        check=True,
    ).stdout.decode()
    paths = {REPO / name for name in listed.split("\0") if name}
    return sorted(p for p in paths if p.is_file() and p != Path(__file__).resolve())


def _text(path: Path) -> str | None:
    """The file's text, or None for a binary file."""
    data = path.read_bytes()
    if b"\0" in data:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def _site_links_to_the_equations(path: Path, line: str) -> str:
    """``line`` without the site's own links to docs/equations.md: a page's relative
    Markdown link that resolves to it, or mkdocs.yml's nav entry (docs_dir-relative)."""
    if path.name == "mkdocs.yml":
        return re.sub(r":\s*equations\.md\s*$", ": docs/equations.md", line)

    def keep(m: re.Match[str]) -> str:
        target = m.group(1).split("#")[0]
        own = (path.parent / target).resolve() == REPO / "docs" / "equations.md"
        return "" if own else m.group(0)

    return MARKDOWN_LINK.sub(keep, line) if path.suffix == ".md" else line


def references_outside(path: Path, text: str) -> list[str]:
    """Each reference in ``text`` (of ``path``) to something outside the repository."""
    found = []
    for number, line in enumerate(text.splitlines(), start=1):
        line = _site_links_to_the_equations(path, line)
        for what, pattern in PATTERNS.items():
            found += [f"{number}: {what}: {m.group(0)!r}" for m in pattern.finditer(line)]
        if path.suffix == ".md":
            for match in MARKDOWN_LINK.finditer(line):
                target = match.group(1).split("#")[0]
                if not target or re.match(r"^[a-z][a-z0-9+.-]*:", target):  # a URL, an anchor
                    continue
                resolved = (path.parent / target).resolve()
                if not resolved.is_relative_to(REPO):
                    found.append(f"{number}: a link out of the repository: {target!r}")
    return found


def test_the_project_documents_its_own_equations() -> None:
    assert (REPO / "docs" / "equations.md").is_file()


def test_no_file_refers_to_anything_outside_the_repository() -> None:
    files = _files()
    assert len(files) > 100, "git ls-files found too few files"  # the scan really ran
    problems = []
    for path in files:
        text = _text(path)
        if text is not None:
            name = path.relative_to(REPO)
            problems += [f"{name}:{line}" for line in references_outside(path, text)]
    assert not problems, "references outside the repository:\n" + "\n".join(problems)


def test_the_guard_finds_what_it_looks_for() -> None:
    here = REPO / "docs" / "note.md"
    bad = (
        "see ../"
        "shared/design/equations.md\n"  # split so this source names no such folder
        "frames in design/equations.md\n"
        "from /work/main/headsim/paper.py and /home/someone/x\n"
        r"C:\Users\someone\file" + "\n"
        "[notes](../../elsewhere.md)\n"
    )
    found = references_outside(here, bad)
    assert [f.split(": ")[1] for f in found] == [
        "a folder beside the checkout",
        "equations.md not as docs/equations.md",
        "equations.md not as docs/equations.md",
        "a machine path",
        "a machine path",
        "a machine path",
        "a link out of the repository",
    ], found
    good = (
        "frames and signs: docs/equations.md (eq. 1); [readme](../README.md)\n"
        "headsim run quickstart --out /tmp/q; #!/usr/bin/env bash; 2>/dev/null\n"
        "https://github.com/Users/x and ~/work/ and /data/r.json\n"
    )
    assert references_outside(here, good) == []
