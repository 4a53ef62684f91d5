"""A sweep's outputs (studies/sweep_output.py): aggregate files in job order, a plot per
numeric field, and the printed table."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import cv2

from headsim.studies.sweep_output import METRICS, summary_table, write_aggregate
from headsim.studies.sweep_spec import load_sweep

SWEEP = Path(__file__).resolve().parents[2] / "sweeps" / "focal.toml"


def _records(spec) -> dict[str, dict]:
    records = {}
    for job in spec.jobs:
        failed = job.index == 2
        records[job.id] = {
            "index": job.index,
            "params": job.params,
            "status": "failed" if failed else "ok",
            "rms_error_pct_depth": None if failed else 0.01 * (job.index + 1),
            "renders": 100 + job.index,
        }
    return records


def test_the_aggregate_has_a_row_per_job_in_order_and_a_plot_per_numeric_field(
    tmp_path: Path,
) -> None:
    spec = load_sweep(SWEEP)
    records = _records(spec)
    files = write_aggregate(spec, dict(reversed(list(records.items()))), tmp_path)
    assert set(files) == {"csv", "json", "plot cam1.kx"}
    with files["csv"].open() as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0]) == ["job", "cam1.kx", *METRICS]
    assert [row["job"] for row in rows] == ["0", "1", "2", "3"]
    assert [float(row["cam1.kx"]) for row in rows] == [600.0, 750.0, 835.0, 1000.0]
    assert [row["status"] for row in rows] == ["ok", "ok", "failed", "ok"]
    data = json.loads(files["json"].read_text())
    assert data["sweep"] == spec.description and len(data["rows"]) == 4
    assert data["rows"][2]["rms_error_pct_depth"] is None
    image = cv2.imread(str(files["plot cam1.kx"]))
    assert image is not None and image.shape == (400, 600, 3)
    assert files["plot cam1.kx"].name == "error_vs_cam1_kx.png"


def test_the_table_lists_jobs_by_index_with_a_dash_for_no_error() -> None:
    spec = load_sweep(SWEEP)
    lines = summary_table(spec, reversed(list(_records(spec).values()))).splitlines()
    assert lines[0].split() == ["job", "cam1.kx", "status", "err", "%z", "renders"]
    assert [line.split()[0] for line in lines[1:]] == ["0", "1", "2", "3"]
    assert lines[1].split() == ["0", "600", "ok", "0.010", "100"]
    assert lines[3].split() == ["2", "835", "failed", "-", "102"]
