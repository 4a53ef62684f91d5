"""Result files: JSON conversion, and atomic writes that leave nothing half-written."""

from __future__ import annotations

import csv
import enum
import json
import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pytest

from headsim.files import (
    to_jsonable,
    write_csv_atomic,
    write_json_atomic,
    write_png_atomic,
    write_text_atomic,
)


class Colour(enum.Enum):
    RED = "red"


@dataclass(frozen=True)
class Point:
    xyz: np.ndarray
    colour: Colour


def test_to_jsonable_turns_numpy_enums_dataclasses_and_nan_into_plain_json() -> None:
    value = {
        1: Point(np.array([0.5, np.nan, 2.0]), Colour.RED),
        "n": np.int64(3),
        "ok": np.bool_(True),
        "path": Path("a/b"),
        "inf": math.inf,
    }
    plain = to_jsonable(value)
    assert plain == {
        "1": {"xyz": [0.5, None, 2.0], "colour": "red"},
        "n": 3,
        "ok": True,
        "path": "a/b",
        "inf": None,
    }
    json.dumps(plain, allow_nan=False)  # strict JSON


def test_json_text_and_csv_read_back_and_leave_no_temporary_file(tmp_path: Path) -> None:
    out = tmp_path / "deep" / "results.json"
    write_json_atomic(out, {"a": np.float32(0.25)})
    assert json.loads(out.read_text()) == {"a": 0.25}
    write_text_atomic(tmp_path / "summary.txt", "x = 1 µm\n")
    assert (tmp_path / "summary.txt").read_text(encoding="utf-8") == "x = 1 µm\n"
    write_csv_atomic(tmp_path / "t.csv", [{"a": 1.23456789, "b": math.nan}, {"a": 2.0, "b": 3}])
    with (tmp_path / "t.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert rows == [{"a": "1.23457", "b": ""}, {"a": "2", "b": "3"}]
    assert not [p for p in tmp_path.rglob(".*.tmp")]


def test_a_failed_write_keeps_the_old_file_whole(tmp_path: Path) -> None:
    out = tmp_path / "results.json"
    write_json_atomic(out, {"run": 1})
    with pytest.raises(TypeError):
        write_json_atomic(out, {"bad": object()})  # not JSON: fails before anything is replaced
    assert json.loads(out.read_text()) == {"run": 1}
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]


def test_png_round_trips_rgb(tmp_path: Path) -> None:
    rgb = np.zeros((4, 5, 3), np.uint8)
    rgb[..., 0] = 200  # red
    write_png_atomic(tmp_path / "a.png", rgb)
    back = cv2.cvtColor(cv2.imread(str(tmp_path / "a.png")), cv2.COLOR_BGR2RGB)
    np.testing.assert_array_equal(back, rgb)
