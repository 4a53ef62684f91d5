"""A sweep's outputs: aggregate.csv/.json with a row per job, a plot per swept field, and
the table printed at the end."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from headsim.studies.output import write_rows
from headsim.studies.sweep_spec import SweepSpec

#: Columns of aggregate.csv after the swept fields.
METRICS = (
    "status",
    "failures",
    "measurements_ok",
    "measurements",
    "rms_error_pct_depth",
    "mean_error_mm",
    "max_error_mm",
    "renders",
    "targets_redrawn",
    "calibration_max_error_rad",
    "attempts",
)


def aggregate_rows(spec: SweepSpec, records: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per job, in job order: the swept fields, then ``METRICS``."""
    rows = []
    for job in spec.jobs:
        record = records[job.id]
        row = {"job": job.index, **{f: job.params.get(f) for f in spec.fields}}
        row.update({m: record.get(m) for m in METRICS})
        rows.append(row)
    return rows


def write_aggregate(
    spec: SweepSpec, records: dict[str, dict[str, Any]], out: Path
) -> dict[str, Path]:
    """aggregate.csv, aggregate.json and one PNG per numeric swept field."""
    rows = aggregate_rows(spec, records)
    document = {"sweep": spec.description, "scenario": spec.scenario, "rows": rows}
    files = write_rows(out, "aggregate", rows, document)
    for name in spec.fields:
        if name == "seed":  # an error against the seed says nothing
            continue
        from headsim.studies.plots import plot_metric  # matplotlib loads only for plots

        png = plot_metric(
            rows, name, "rms_error_pct_depth", out / f"error_vs_{_slug(name)}.png", spec.description
        )
        if png is not None:
            files[f"plot {name}"] = png
    return files


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in name)


def _cell(value: Any) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def summary_table(spec: SweepSpec, records: Iterable[dict[str, Any]]) -> str:
    """A readable table of the jobs."""
    lines = [
        "  ".join(
            [
                f"{'job':>4s}",
                *(f"{f:>16s}" for f in spec.fields),
                f"{'status':>8s}",
                f"{'err %z':>8s}",
                f"{'renders':>7s}",
            ]
        )
    ]
    by_index = sorted(records, key=lambda r: r["index"])
    for r in by_index:
        values = [f"{_cell(r['params'].get(f)):>16s}" for f in spec.fields]
        err = r.get("rms_error_pct_depth")
        lines.append(
            "  ".join(
                [
                    f"{r['index']:4d}",
                    *values,
                    f"{r.get('status', '?'):>8s}",
                    f"{err:8.3f}" if err is not None else f"{'-':>8s}",
                    f"{r.get('renders', '-')!s:>7s}",
                ]
            )
        )
    return "\n".join(lines)
