"""Every benchmark as a case of ``headsim bench``: one registry, one command, one listing.

A :class:`BenchCase` is either a part of the regression suite
(:data:`headsim.studies.bench.PARTS`: machine-independent metrics compared
with ``benchmarks/baseline.json`` within ``benchmarks/tolerances.json``; CI
runs them through ``make regress``) or a figures case: a script in
``benchmarks/`` that prints its figures (minutes to hours, not compared with
anything).  ``headsim bench`` runs the regression cases; ``--case NAME`` any
case (a figures case takes its script's own arguments after ``--``);
``--all`` the regression cases, then every figures case that takes minutes
(the ``long`` ones run only by name); ``--list`` shows them all.
"""

from __future__ import annotations

import ast
import subprocess
import sys
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


#: Every case, the regression suite's parts first (in :data:`headsim.studies.bench.PARTS`'
#: order), then the figures scripts, then the long ones.
CASES: dict[str, BenchCase] = {
    case.name: case
    for case in (
        BenchCase("ideal", "regress", summary="Model 2 on ideal cameras, with and without windows"),
        BenchCase(
            "paper",
            "regress",
            summary="the paper's cameras: Sec. V calibration, Model 2, chessboard, areas",
        ),
        BenchCase(
            "realistic",
            "regress",
            summary="the realistic head: extended calibration, Model 2 over the whole field",
        ),
        BenchCase("scenarios", "regress", summary="the paper scenarios' fast variants"),
        BenchCase(
            "speed", "regress", summary="estimator throughput, the quick start over one render"
        ),
        BenchCase("render_speed", "figures", "render_speed.py"),
        BenchCase("estimators_throughput", "figures", "estimators_throughput.py"),
        BenchCase("vision_speed", "figures", "vision_speed.py"),
        BenchCase("stereo_calibration", "figures", "stereo_calibration.py"),
        BenchCase("procedures_accuracy", "figures", "procedures_accuracy.py"),
        BenchCase("live_gaze", "figures", "live_gaze.py"),
        BenchCase("gym_env", "figures", "gym_env.py"),
        BenchCase("batch_render", "figures", "batch_render.py"),
        BenchCase("batch_env", "figures", "batch_env.py"),
        BenchCase("scene_cost", "figures", "scene_cost.py"),
        BenchCase("search_cases", "long", "search_cases.py"),
        BenchCase("batch_sweep", "long", "batch_sweep.py"),
        BenchCase("batch_device", "long", "batch_device.py"),
        BenchCase("lockstep_model2", "long", "lockstep_model2.py"),
        BenchCase("lockstep_servo_host", "long", "lockstep_servo_host.py"),
        BenchCase("render_fidelity", "long", "render_fidelity.py"),
        BenchCase("relative_areas", "long", "relative_areas.py"),
        BenchCase("reach_and_zoom", "long", "reach_and_zoom.py"),
        BenchCase("realistic_head", "long", "realistic_head.py"),
        BenchCase("insensitivity_study", "long", "insensitivity_study.py"),
        BenchCase("heads", "long", "heads.py"),
    )
}


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
