"""The campaigns' one writer (studies/output.py): rows to CSV, the document to JSON, the
figure by the campaign's hook, each under the campaign's stem."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from headsim.studies.output import write_rows

pytestmark = pytest.mark.fast


def test_rows_document_and_figure_are_written_under_one_stem(tmp_path: Path) -> None:
    rows = [{"job": 0, "rms_mm": 1.234567891}, {"job": 1, "rms_mm": float("nan")}]
    drawn: list[Path] = []
    files = write_rows(tmp_path, "budget", rows, {"fast": True, "rows": rows[:1]}, drawn.append)
    assert files == {
        "csv": tmp_path / "budget.csv",
        "json": tmp_path / "budget.json",
        "png": tmp_path / "budget.png",
    }
    with files["csv"].open(newline="") as handle:
        assert list(csv.DictReader(handle)) == [
            {"job": "0", "rms_mm": "1.23457"},
            {"job": "1", "rms_mm": ""},
        ]
    assert json.loads(files["json"].read_text()) == {
        "fast": True,
        "rows": [{"job": 0, "rms_mm": 1.234567891}],
    }
    assert drawn == [files["png"]]


def test_without_a_figure_hook_no_png_is_named(tmp_path: Path) -> None:
    files = write_rows(tmp_path, "aggregate", [{"a": 1}], {"rows": [{"a": 1}]})
    assert sorted(files) == ["csv", "json"] and not (tmp_path / "aggregate.png").exists()
