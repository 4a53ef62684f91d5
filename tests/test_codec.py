"""headsim.codec: a declared type's JSON, read back, and its reference, from one declaration."""

from __future__ import annotations

import enum
import json
import math
from typing import Any

import numpy as np
import pytest

from headsim.active.calibration_report import CalibrationReport
from headsim.codec import declared, decode, describe, doc, encode, keys
from headsim.files import to_jsonable
from headsim.runs.outcomes import RunRenders
from headsim.runs.serialise import EstimateDocument, ResultsDocument
from headsim.sim.events import RenderCounts
from headsim.stereo.calibration import StereoCalibration

pytestmark = pytest.mark.fast


class Colour(enum.Enum):
    RED = "red"


@declared
class Inner:
    """A nested type: a list of its entries, with a key nested one table down."""

    depth_m: float = doc("depth, m")
    spread_m: float = doc("its spread, m", key="errors.spread_m")


def _state(text: str) -> dict[str, Any]:
    return {"state": text.upper(), "note": text}


@declared
class Outer:
    """Every kind of declaration the result files use."""

    state: str = doc("written from the whole object", write=lambda o: o.note, read=_state)
    note: str = doc("set by state's read", skip=True)
    colour: Colour = doc("an enum, by value")
    pose: np.ndarray = doc("a 2 x 2 array", shape=(2, 2))
    pair: tuple[int, int] = doc("two counts")
    inner: tuple[Inner, ...] = doc("entries")
    by_name: dict[str, Inner] = doc("tables keyed by data", each="one name")
    layout: str | None = doc("written only while set, and the next with it", default=None)
    scale: float = doc("only with layout", default=1.0, only_with="layout")
    origin: str | None = doc("left out while None", default=None, omit_if_none=True, key="from")


def _outer(**changes: Any) -> Outer:
    values: dict[str, Any] = {
        "state": "OK",
        "note": "ok",
        "colour": Colour.RED,
        "pose": np.eye(2),
        "pair": (1, 2),
        "inner": (Inner(0.5, 0.01),),
        "by_name": {"a": Inner(1, math.nan)},
        **changes,
    }
    return Outer(**values)


def _json(value: Any) -> str:
    return json.dumps(to_jsonable(value), indent=2, allow_nan=False)


def test_a_declared_type_writes_its_keys_in_order_nesting_and_leaving_out_as_declared() -> None:
    plain = encode(_outer())
    assert list(plain) == ["state", "colour", "pose", "pair", "inner", "by_name", "layout"]
    assert plain["state"] == "ok" and plain["colour"] == "red" and plain["pair"] == [1, 2]
    assert plain["inner"] == [{"depth_m": 0.5, "errors": {"spread_m": 0.01}}]
    laid = encode(_outer(layout="grid", origin="file"))
    assert list(laid)[-3:] == ["layout", "scale", "from"] and laid["from"] == "file"
    assert keys(Outer)[-1] == "from" and keys(Inner) == ("depth_m", "errors")


def test_what_was_written_reads_back_equal_and_writes_the_same_bytes() -> None:
    original = _outer(layout="grid", scale=2, origin="file")
    text = _json(encode(original))
    back = decode(Outer, json.loads(text))
    assert back.state == "OK" and back.note == "ok" and back.colour is Colour.RED
    assert np.array_equal(back.pose, original.pose) and back.pair == (1, 2)
    assert back.inner == original.inner and back.by_name["a"].depth_m == 1
    # A whole number declared as a float stays whole, so it is written as it was read.
    assert isinstance(back.scale, int) and _json(encode(back)) == text
    assert math.isnan(original.by_name["a"].spread_m) and '"spread_m": null' in text


def test_a_malformed_table_names_the_key_and_what_was_wrong() -> None:
    good = json.loads(_json(encode(_outer())))
    with pytest.raises(KeyError, match="colour"):
        decode(Outer, {k: v for k, v in good.items() if k != "colour"})
    with pytest.raises(ValueError, match=r"pose: not 2 x 2 finite numbers"):
        decode(Outer, {**good, "pose": [[1.0, 0.0]]})
    with pytest.raises(ValueError, match=r"pose: not 2 x 2"):
        decode(Outer, {**good, "pose": [[1.0, math.inf], [0.0, 1.0]]})
    with pytest.raises(TypeError, match=r"inner\[\]\.depth_m: float expected, got 'near'"):
        decode(Outer, {**good, "inner": [{"depth_m": "near", "errors": {"spread_m": 0}}]})
    with pytest.raises(KeyError, match=r"by_name\.a\.errors\.spread_m"):
        decode(Outer, {**good, "by_name": {"a": {"depth_m": 1.0}}})
    with pytest.raises(ValueError, match="pair: 2 values expected, got 3"):
        decode(Outer, {**good, "pair": [1, 2, 3]})
    assert decode(Outer, good, colour=Colour.RED, pair=(5, 6)).pair == (5, 6)


def test_the_reference_lists_every_key_by_its_path() -> None:
    fields = describe(Outer)
    assert fields["state"] == "written from the whole object" and "note" not in fields
    assert fields["inner[].errors.spread_m"] == "its spread, m"
    assert fields["by_name.*"] == "one name" and fields["by_name.*.depth_m"] == "depth, m"
    assert fields["from"] == "left out while None"
    assert list(fields)[:3] == ["state", "colour", "pose"]


@pytest.mark.parametrize(
    "cls", [ResultsDocument, EstimateDocument, CalibrationReport, StereoCalibration]
)
def test_every_key_of_the_result_files_has_a_meaning(cls: type) -> None:
    fields = describe(cls)
    assert len(fields) >= 10 and [path for path, meaning in fields.items() if not meaning] == []


@declared
class Figures:
    """Figures written beside their owner's keys."""

    frames: int = doc("frames run")
    lag_s: float = doc("lag, s", default=math.nan)


@declared
class WithFigures:
    """A spec, then its figures flat beside it (left out while None)."""

    spec: dict[str, Any] = doc("the spec")
    figures: Figures | None = doc("the figures", default=None, flat=True, omit_if_none=True)


def test_a_flat_field_writes_reads_and_describes_its_keys_beside_its_owners() -> None:
    whole = WithFigures({"kind": "jump"}, Figures(3, 0.25))
    block = encode(whole)
    assert block == {"spec": {"kind": "jump"}, "frames": 3, "lag_s": 0.25}
    assert decode(WithFigures, block) == whole
    assert encode(WithFigures({"kind": "jump"})) == {"spec": {"kind": "jump"}}
    assert decode(WithFigures, {"spec": {}}).figures is None
    assert keys(WithFigures) == ("spec", "frames", "lag_s")
    assert describe(WithFigures) == {"spec": "the spec", "frames": "frames run", "lag_s": "lag, s"}


def test_render_counts_write_their_total_and_each_phase_and_read_back() -> None:
    calibration, experiment = RenderCounts(images=2, previews=1), RenderCounts(3, 4, 1, 0)
    renders = RunRenders(calibration, experiment, in_measurements=6)
    block = encode(renders)
    assert block["calibration"] == {
        "images": 2,
        "windows": 0,
        "retakes": 0,
        "previews": 1,
        "total": 3,
    }
    assert block["experiment"] == {
        **{"images": 3, "windows": 4, "retakes": 1, "previews": 0, "total": 8},
        **{"in_measurements": 6, "outside_measurements": 2},
    }
    assert block["overall"]["total"] == 11 and list(block) == [
        "calibration",
        "experiment",
        "overall",
    ]
    assert decode(RenderCounts, block["experiment"]) == experiment
    assert decode(RunRenders, block) == renders
