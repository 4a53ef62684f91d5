"""Every benchmark as a case of ``headsim bench``: one file, one command, one listing.

A :class:`BenchCase` is either a part of the regression suite
(:data:`headsim.studies.bench.PARTS`: machine-independent metrics compared
with ``benchmarks/baseline.json`` within ``benchmarks/tolerances.json``; CI
runs them through ``make regress``) or a figures case: a script in
``benchmarks/`` that prints its figures (minutes to hours, not compared with
anything).  The cases are declared in ``bench_cases.toml`` beside this module.
``headsim bench`` runs the regression cases; ``--case NAME`` any
case (a figures case takes its script's own arguments after ``--``);
``--all`` the regression cases, then every figures case that takes minutes
(the ``long`` ones run only by name); ``--list`` shows them all.
"""

from __future__ import annotations

import ast
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

from headsim.studies.checks import BENCH_DIR

#: A case's kind: compared with the baseline, figures of minutes, figures of longer.
KINDS = ("regress", "figures", "long")


@dataclass(frozen=True)
class BenchCase:
    """One benchmark: ``name``, its ``kind`` (one of :data:`KINDS`) and, for a figures
    case, its ``script`` in ``benchmarks/``; ``summary`` for a regression case (a
    script's is its docstring's first line)."""

    name: str
    kind: str
    script: str | None = None
    summary: str = ""

    @property
    def path(self) -> Path | None:
        """The figures case's script (None for a regression case)."""
        return None if self.script is None else BENCH_DIR / self.script

    def description(self) -> str:
        """One line: the regression part's summary, or the script's docstring's first line."""
        path = self.path
        if path is None:
            return self.summary
        if not path.is_file():
            return f"(needs a checkout of the repository: {self.script} not found)"
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        return doc.splitlines()[0] if doc else ""


#: The file that declares every case (see its header).
CASES_FILE = Path(__file__).with_name("bench_cases.toml")


def _load(path: Path) -> dict[str, BenchCase]:
    """The cases ``path`` declares, in its order: a regression case's value is its
    summary, a figures or long case's its script in ``benchmarks/``."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    unknown = set(data) - set(KINDS)
    if unknown:
        raise ValueError(f"{path.name}: unknown tables {sorted(unknown)}; allowed: {KINDS}")
    return {
        name: (
            BenchCase(name, kind, summary=value)
            if kind == "regress"
            else BenchCase(name, kind, script=value)
        )
        for kind in KINDS
        for name, value in data.get(kind, {}).items()
    }


#: Every case, the regression suite's parts first (in the order they run), then the
#: figures scripts, then the long ones.
CASES: dict[str, BenchCase] = _load(CASES_FILE)


def case(name: str) -> BenchCase:
    """The case named ``name`` (KeyError naming the known ones)."""
    try:
        return CASES[name]
    except KeyError:
        raise KeyError(f"no bench case named {name!r}; known: {', '.join(CASES)}") from None


def of_kind(*kinds: str) -> tuple[BenchCase, ...]:
    """The cases of the given kinds, in registry order."""
    return tuple(c for c in CASES.values() if c.kind in kinds)


def listing() -> list[str]:
    """``headsim bench --list``: one line per case, its kind and what it measures."""
    width = max(len(name) for name in CASES)
    return [f"{c.name:<{width}}  {c.kind:<8} {c.description()}" for c in CASES.values()]


def run_script(bench_case: BenchCase, arguments: list[str]) -> int:
    """Run a figures case's script with ``arguments`` in this interpreter; its exit status
    (1 where a signal ended it, so that a crash never reads as success)."""
    path = bench_case.path
    assert path is not None, f"{bench_case.name} is a regression case, not a script"
    if not path.is_file():
        print(
            f"headsim bench: {bench_case.name} needs a checkout of the repository "
            f"({path} not found)",
            file=sys.stderr,
        )
        return 2
    print(f"== {bench_case.name}: {bench_case.description()}", flush=True)
    code = subprocess.run([sys.executable, str(path), *arguments], check=False).returncode
    return code if code >= 0 else 1


__all__ = ["CASES", "KINDS", "BenchCase", "case", "listing", "of_kind", "run_script"]
