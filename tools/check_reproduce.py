"""Check a ``headsim reproduce`` report against the stored baseline (CI runs it).

Fails (exit 1) when the run did not finish ok, when an experiment of the
baseline is missing or failed, when a row the baseline reproduced is no
longer reproduced, or when the wall ratio's unit is not the quieter of the
two render medians it was timed as.  ``--update`` stores the report's rows as the new baseline.

    python tools/check_reproduce.py out/reproduce/report.json [--update]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

BASELINE = Path(__file__).resolve().parents[1] / "benchmarks" / "reproduce_baseline.json"


def problems(report: dict, baseline: dict) -> list[str]:
    """What the report lost against the baseline, one line each (empty: ok)."""
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


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("report", help="report.json written by headsim reproduce")
    parser.add_argument("--baseline", default=str(BASELINE))
    parser.add_argument("--update", action="store_true", help="store this report as the baseline")
    args = parser.parse_args()
    report = json.loads(Path(args.report).read_text())
    if args.update:
        keep = {"status": report["status"], "fast": report["fast"], "rows": report["rows"]}
        Path(args.baseline).write_text(json.dumps(keep, indent=2) + "\n")
        print(f"baseline written to {args.baseline}")
        return 0
    found = problems(report, json.loads(Path(args.baseline).read_text()))
    for line in found:
        print(f"reproduce regressed: {line}", file=sys.stderr)
    reproduced = sum(
        r["verdict"].startswith("reproduced")
        for rows in report.get("rows", {}).values()
        for r in rows or []
    )
    print(f"reproduce report: {reproduced} rows reproduced; {len(found)} regression(s)")
    return 1 if found else 0


if __name__ == "__main__":
    raise SystemExit(main())
