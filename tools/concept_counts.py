"""The figures of issue 42's "done when": the package's size, and the files a researcher
touches to add a procedure, a head or an imperfection.

    python tools/concept_counts.py [REPO_ROOT]

A report, not a test: it prints counts and the files behind them, and exits 0.

- **Lines**: every ``headsim/**/*.py`` file's lines, raw, non-blank, and non-blank
  without the comment-only ones (docstrings count as code).
- **A procedure**: the files CONTRIBUTING.md's "Adding a procedure" names (a step
  counts only while its words are still in the recipe), plus every file outside
  ``headsim/procedures/`` that names each registered procedure: a complete list (an
  import order, a reference table, a test pinning the registry) that a new one joins.
- **A head**: CONTRIBUTING.md's "Adding a head" (else a user's head, docs/how-to/
  own-head.md's MJCF file and scenario file, and a shipped head's model file and test),
  plus every file that lists each shipped head but ``paper`` (all named within
  ``LIST_SPAN`` lines: a table, a dict, an error's choices); files that name them only
  apart, as examples, are shown beside it and not counted.
- **An imperfection**: CONTRIBUTING.md's recipe if it has one, else the files that
  name the image noise (``noise_std``, one setting every renderer applies) in code or
  in a docs page's code span: where an image imperfection is declared, ranged,
  described, applied and recorded today.

Names are matched as whole words in Python identifiers, imports and string literals
(not comments or docstrings), and in Markdown code spans; scenario files are left
out, and so is this file.
"""

from __future__ import annotations

import ast
import io
import re
import sys
import tokenize
from pathlib import Path

#: "Adding a procedure", read from CONTRIBUTING.md: (the file, words that ask for it).
PROCEDURE_RECIPE = (
    ("headsim/procedures/NAME.py", "**The module**, `headsim/procedures/NAME.py`"),
    ("scenarios/NAME.toml", "**A scenario file** in `scenarios/`"),
    ("tests/procedures/test_NAME.py", "**Its tests**, `tests/procedures/test_NAME.py`"),
)
#: "Adding an image imperfection", read from CONTRIBUTING.md likewise.
IMPERFECTION_RECIPE = (
    ("headsim/sim/imperfections/NAME.py", "is one module in `headsim/sim/imperfections/`"),
    ("tests/sim/test_NAME.py", "adding one means the module and its test"),
)
#: A user's own head, read from docs/how-to/own-head.md: the MJCF file and its scenario.
OWN_HEAD = ("my_head.xml", "scenarios/NAME.toml")
#: "Adding a head", read from CONTRIBUTING.md likewise.
HEAD_RECIPE = (
    ("models/NAME.xml", "**The model**, `models/NAME.xml`"),
    ("tests/models/test_NAME.py", "**Its test**, `tests/models/test_NAME.py`"),
)
#: Lines within which a file must name every shipped head to hold a list of them.
LIST_SPAN = 6
#: The existing imperfection a new image imperfection follows.
IMPERFECTION = "noise_std"
SEARCHED = ("headsim", "tests", "docs", "tools", "benchmarks", "examples")


def line_counts(package: Path) -> tuple[int, int, int, int]:
    """Modules, raw lines, non-blank lines, non-blank lines that are not comments alone."""
    modules = raw = non_blank = code = 0
    for path in sorted(package.rglob("*.py")):
        text = path.read_text()
        lines = text.splitlines()
        modules += 1
        raw += len(lines)
        non_blank += sum(1 for line in lines if line.strip())
        comment_only = {
            token.start[0]
            for token in tokenize.generate_tokens(io.StringIO(text).readline)
            if token.type == tokenize.COMMENT
            and not lines[token.start[0] - 1].split("#")[0].strip()
        }
        code += sum(1 for n, line in enumerate(lines, 1) if line.strip() and n not in comment_only)
    return modules, raw, non_blank, code


def located_words(path: Path) -> list[tuple[str, int]]:
    """The whole words a file names in code (identifiers, imports, string literals) or,
    for Markdown, in code spans; each with its line."""
    text = path.read_text(errors="replace")
    if path.suffix == ".md":
        return [
            (w, n)
            for n, line in enumerate(text.splitlines(), 1)
            for span in re.findall(r"`([^`\n]+)`", line)
            for w in re.findall(r"\w+", span)
        ]
    tree = ast.parse(text)
    docstrings = {
        id(node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
    }
    found: list[tuple[str, int]] = []
    for node in ast.walk(tree):
        line = getattr(node, "lineno", 0)
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            if id(node) in docstrings:
                continue
            found += [(w, line) for w in re.findall(r"\w+", node.value)]
        elif isinstance(node, ast.Name):
            found.append((node.id, line))
        elif isinstance(node, ast.Attribute):
            found.append((node.attr, line))
        elif isinstance(node, ast.alias):
            found += [(w, line) for w in node.name.split(".")]
        elif isinstance(node, ast.arg | ast.keyword) and node.arg:
            found.append((node.arg, line))
        elif isinstance(node, ast.ImportFrom) and node.module:
            found += [(w, line) for w in node.module.split(".")]
    return found


def words(path: Path) -> set[str]:
    """The whole words a file names in code or in Markdown code spans."""
    return {w for w, _ in located_words(path)}


def listing_all(root: Path, files: list[str], names: set[str]) -> list[str]:
    """Of ``files``, those that name every one of ``names`` within :data:`LIST_SPAN`
    lines: a list (a table, a dict, an error message's choices) that a new one joins,
    not examples that name one each."""
    listing = []
    for f in files:
        lines: dict[str, list[int]] = {}
        for w, n in located_words(root / f):
            if w in names:
                lines.setdefault(w, []).append(n)
        starts = sorted({n for found in lines.values() for n in found})
        if len(lines) == len(names) and any(
            all(any(s <= n < s + LIST_SPAN for n in found) for found in lines.values())
            for s in starts
        ):
            listing.append(f)
    return listing


def searched_files(root: Path) -> dict[str, set[str]]:
    files = [
        p for d in SEARCHED for p in sorted((root / d).rglob("*")) if p.suffix in (".py", ".md")
    ]
    this = Path(__file__).resolve()
    return {
        str(p.relative_to(root)): words(p)
        for p in files
        if ".venv" not in p.parts and p.resolve() != this
    }


def naming_all(index: dict[str, set[str]], names: set[str], skip: str = "") -> list[str]:
    """Files that name every one of ``names`` (outside the folder ``skip``)."""
    return [f for f, found in index.items() if names <= found and not (skip and f.startswith(skip))]


def procedures(root: Path) -> set[str]:
    """Each registered procedure's name: ``Procedure("name", ...)`` in headsim/."""
    found = set()
    for path in (root / "headsim").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Call)
                and getattr(node.func, "attr", getattr(node.func, "id", "")) == "Procedure"
                and node.args
                and isinstance(node.args[0], ast.Constant)
            ):
                found.add(str(node.args[0].value))
    return found


def section(text: str, title: str) -> str | None:
    """A Markdown section's text, whitespace collapsed (None: no such section)."""
    match = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    return " ".join(match.group(1).split()) if match else None


def report(title: str, files: list[str], notes: str = "") -> None:
    print(f"{title}: {len(files)} files{notes}")
    for f in files:
        print(f"    {f}")


def main() -> int:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1]
    modules, raw, non_blank, code = line_counts(root / "headsim")
    print(
        f"package headsim/: {modules} modules; lines: {raw} raw, {non_blank} non-blank, "
        f"{code} non-blank and not comment-only"
    )
    index = searched_files(root)
    contributing = (root / "CONTRIBUTING.md").read_text()

    recipe = section(contributing, "Adding a procedure") or ""
    asked = [
        f if (root / f).exists() or "NAME" in f else f"{f} (generated: not in the repository)"
        for f, words_ in PROCEDURE_RECIPE
        if " ".join(words_.split()) in recipe
    ]
    gone = [f for f, words_ in PROCEDURE_RECIPE if " ".join(words_.split()) not in recipe]
    if gone:  # the recipe was rewritten: PROCEDURE_RECIPE must be read from it again
        print("steps of PROCEDURE_RECIPE no longer in CONTRIBUTING.md:", ", ".join(gone))
    registered = procedures(root)
    lists = naming_all(index, registered, skip="headsim/procedures/")
    print(f"\nregistered procedures: {len(registered)}")
    report("a new procedure, CONTRIBUTING.md's recipe", asked)
    report("  files naming every procedure (outside procedures/)", lists)
    report("  together", sorted({*asked, *lists}))

    print()
    shipped = {p.stem for p in (root / "models").glob("*.xml") if p.stem not in ("head",)} - {
        p.stem for p in (root / "models").glob("scene*.xml")
    }
    head_recipe = section(contributing, "Adding a head")
    head_named = naming_all(index, shipped)
    head_lists = listing_all(root, head_named, shipped)
    if head_recipe is None:
        report(
            "a user's own head (no CONTRIBUTING recipe; docs/how-to/own-head.md)", list(OWN_HEAD)
        )
        steps = ["models/NAME.xml", "tests/models/test_NAME.py"]
    else:
        steps = [f for f, w in HEAD_RECIPE if " ".join(w.split()) in head_recipe]
        gone = [f for f, w in HEAD_RECIPE if " ".join(w.split()) not in head_recipe]
        if gone:
            print("steps of HEAD_RECIPE no longer in CONTRIBUTING.md:", ", ".join(gone))
    report(
        f"a shipped head: {'CONTRIBUTING.md' + chr(39) + 's recipe' if head_recipe else 'its model and test'}, "
        f"and files listing every shipped head but paper ({', '.join(sorted(shipped))}) "
        f"within {LIST_SPAN} lines",
        sorted({*steps, *head_lists}),
    )
    report(
        "  files naming each of them apart (examples, not lists)",
        sorted(set(head_named) - set(head_lists)),
    )

    print()
    imperfection = section(contributing, "Adding an image imperfection")
    if imperfection is None:
        named = sorted(f for f, found in index.items() if IMPERFECTION in found)
        package = [f for f in named if f.startswith("headsim/")]
        areas = sorted({f.split("/")[1] for f in package if f.count("/") > 1})
        elsewhere = {d: sum(f.startswith(f"{d}/") for f in named) for d in SEARCHED[1:]}
        report(
            f"a new imperfection (no CONTRIBUTING recipe): package files naming {IMPERFECTION}",
            package,
            f" in {len(areas)} packages ({', '.join(areas)})",
        )
        print("    and", ", ".join(f"{n} in {d}/" for d, n in elsewhere.items() if n))
    else:
        steps = [f for f, w in IMPERFECTION_RECIPE if " ".join(w.split()) in imperfection]
        gone = [f for f, w in IMPERFECTION_RECIPE if " ".join(w.split()) not in imperfection]
        if gone:
            print("steps of IMPERFECTION_RECIPE no longer in CONTRIBUTING.md:", ", ".join(gone))
        report("a new image imperfection, CONTRIBUTING.md's recipe", steps)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
