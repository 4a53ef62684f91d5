"""The campaigns' checks, over their rows: the bench's metrics against the stored baseline
and its tolerances (:func:`compare`); the paper's figures and how close to them counts as
reproduced (``headsim reproduce``'s verdicts, :mod:`headsim.studies.reproduce_rows`); and a
reproduce report's rows against those the stored report reproduced
(:func:`reproduce_problems`)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from headsim import paper

BENCH_DIR = Path(__file__).resolve().parents[2] / "benchmarks"
BASELINE = BENCH_DIR / "baseline.json"
TOLERANCES = BENCH_DIR / "tolerances.json"
#: The rows of a ``headsim reproduce --fast`` report that CI holds each run to.
REPRODUCE_BASELINE = BENCH_DIR / "reproduce_baseline.json"


Metrics = dict[str, float]

#: The paper's figures (Sec. VI, :mod:`headsim.paper`), in mm to the paper's digits.
PAPER_ALPHA_E = paper.INITIAL_DIRECTIONS_RAD
PAPER_SIDE_MEAN_MM, PAPER_SIDE_STD_MM, TRUE_SIDE_MM = (
    round(1e3 * side_m, 6)
    for side_m in (
        paper.CHESSBOARD_SIDE_MEAN_M,
        paper.CHESSBOARD_SIDE_STD_M,
        paper.CHESSBOARD_SQUARE_M,
    )
)
#: A square side's std agrees with the paper's when ours over the paper's lies in these
#: bounds: a head several times more precise than the paper's rig does not reproduce it.
SIDE_STD_RATIO = (0.5, 2.0)
#: A square side's mean agrees with the paper's when they differ by at most the paper's std
#: of one side.
SIDE_MEAN_TOLERANCE_MM = PAPER_SIDE_STD_MM
#: "Very close to stereovision" (Sec. VI-B) read as: RMS error at most this times stereo's.
CLOSE_TO_STEREO = 2.0
#: "Insensitive to the intrinsic parameters" read as: RMS after the zoom at most this times before.
INSENSITIVE = 2.0


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


def reproduce_problems(report: dict[str, Any], baseline: dict[str, Any]) -> list[str]:
    """What a reproduce report lost against the baseline, one line each (empty: ok): a run
    not ok, an experiment of the baseline missing, a row the baseline reproduced no longer
    reproduced, or a wall ratio whose unit is not the quieter of its two render medians."""
    found = []
    if report.get("status") != "ok":
        found.append(f"status {report.get('status')!r}, not 'ok'")
    medians = [report.get("render_before_s"), report.get("render_after_s")]
    if all(isinstance(m, float) for m in medians) and "render_s" in report:
        unit = min(medians)  # type: ignore[type-var]
        if report["render_s"] != unit:
            found.append(f"render unit {report['render_s']} s, not the quieter median {unit} s")
        elif (
            abs(report["wall_over_render"] - report["wall_s"] / unit)
            > 1e-6 * report["wall_s"] / unit
        ):
            found.append("wall ratio is not the wall time over the render unit")
    rows_now = report.get("rows", {})
    for experiment, rows in baseline.get("rows", {}).items():
        now = rows_now.get(experiment)
        if now is None:
            found.append(f"{experiment}: no result")
            continue
        verdicts = {r["quantity"]: r["verdict"] for r in now}
        for row in rows or []:
            if not row["verdict"].startswith("reproduced"):
                continue
            verdict = verdicts.get(row["quantity"])
            if verdict is None or not verdict.startswith("reproduced"):
                found.append(f"{experiment}: {row['quantity']}: {verdict or 'missing'}")
    return found


def load_json(path: Path) -> dict[str, Any]:
    return json.loads(path.read_text()) if path.exists() else {}
