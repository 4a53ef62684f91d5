"""The bench's baseline and tolerances, and comparing a run's metrics with them."""

from __future__ import annotations

import json
import math
import platform
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from headsim.version import __version__

BENCH_DIR = Path(__file__).resolve().parents[2] / "benchmarks"
BASELINE = BENCH_DIR / "baseline.json"
TOLERANCES = BENCH_DIR / "tolerances.json"


Metrics = dict[str, float]


@dataclass(frozen=True)
class Verdict:
    """One metric compared with its baseline."""

    metric: str
    baseline: float | None
    now: float
    change: float | None
    allowed: float | None
    regressed: bool

    @property
    def label(self) -> str:
        if self.baseline is None:
            return "new"
        return "REGRESSED" if self.regressed else "ok"


def compare(
    metrics: Metrics, baseline: Metrics, tolerances: dict[str, dict[str, Any]]
) -> list[Verdict]:
    """Each metric against the baseline: worse by more than ``abs + rel * |baseline|`` regresses.

    ``tolerances[metric]`` = {"worse": "higher" or "lower", "abs": float, "rel": float}.
    A metric without a tolerance entry is reported, never failed.
    """
    verdicts = []
    for metric, now in metrics.items():
        base = baseline.get(metric)
        rule = tolerances.get(metric)
        if base is None or rule is None:
            verdicts.append(Verdict(metric, base, now, None, None, False))
            continue
        allowed = float(rule.get("abs", 0.0)) + float(rule.get("rel", 0.0)) * abs(base)
        worse_by = (now - base) if rule["worse"] == "higher" else (base - now)
        regressed = not math.isfinite(now) or worse_by > allowed
        verdicts.append(Verdict(metric, base, now, now - base, allowed, regressed))
    return verdicts


def format_table(verdicts: list[Verdict]) -> str:
    """The comparison as a readable table."""
    lines = [
        f"{'metric':54s} {'baseline':>12s} {'now':>12s} {'change':>11s} {'allowed':>10s}  verdict"
    ]
    for v in verdicts:
        base = "-" if v.baseline is None else f"{v.baseline:12.5g}"
        change = "-" if v.change is None else f"{v.change:+11.3g}"
        allowed = "-" if v.allowed is None else f"{v.allowed:10.3g}"
        lines.append(
            f"{v.metric:54s} {base:>12s} {v.now:12.5g} {change:>11s} {allowed:>10s}  {v.label}"
        )
    return "\n".join(lines)


def load_json(path: Path) -> dict[str, Any]:
    return json.loads(path.read_text()) if path.exists() else {}


def environment() -> dict[str, str]:
    import mujoco

    return {
        "headsim": __version__,
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
    }
