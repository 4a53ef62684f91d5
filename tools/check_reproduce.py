"""Check a ``headsim reproduce`` report against the stored baseline (CI runs it).

Fails (exit 1) when the run did not finish ok, when an experiment of the
baseline is missing or failed, when a row the baseline reproduced is no
longer reproduced, or when the wall ratio's unit is not the quieter of the
two render medians it was timed as (``headsim.studies.checks.reproduce_problems``).
``--update`` stores the report's rows as the new baseline.

    python tools/check_reproduce.py out/reproduce/report.json [--update]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from headsim.studies.checks import REPRODUCE_BASELINE, reproduce_problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("report", help="report.json written by headsim reproduce")
    parser.add_argument("--baseline", default=str(REPRODUCE_BASELINE))
    parser.add_argument("--update", action="store_true", help="store this report as the baseline")
    args = parser.parse_args()
    report = json.loads(Path(args.report).read_text())
    if args.update:
        keep = {"status": report["status"], "fast": report["fast"], "rows": report["rows"]}
        Path(args.baseline).write_text(json.dumps(keep, indent=2) + "\n")
        print(f"baseline written to {args.baseline}")
        return 0
    found = reproduce_problems(report, json.loads(Path(args.baseline).read_text()))
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
