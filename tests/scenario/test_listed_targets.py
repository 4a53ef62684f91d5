"""``[[scene.room.targets]]``: listed markerless targets, each a point on an object (in its
frame) or a world point on a surface, checked when the scenario is read; a point off its
surface, an unknown object or a missing point is a one-line error naming the field."""

from __future__ import annotations

from typing import Any

import pytest

from headsim.scenario.loading import (
    load_scenario,
    read_toml,
    resolve_path,
    scenario_from_document,
    set_field,
)
from headsim.scenario.spec import Scenario
from headsim.scenario.tables import ScenarioError

PATH = resolve_path("natural_field")
POSTER = {"name": "poster_centre", "object": "poster", "point_object_m": [0.05, -0.02, 0.0]}
ON_POSTER = {"name": "on_poster", "point_world_m": [-0.35, 1.6, 0.1]}


def _load(targets: list[dict[str, Any]]) -> Scenario:
    doc = set_field(read_toml(PATH), "scene.room.targets", targets)
    return scenario_from_document(doc, "natural_field", directory=PATH.parent)


def test_listed_targets_are_kept_in_file_order_and_none_is_drawn() -> None:
    spec = _load([POSTER, ON_POSTER]).scene.surface_targets
    assert spec is not None and spec.count == 0
    assert [(t.name, t.body, t.point_m) for t in spec.listed] == [
        ("poster_centre", "poster", (0.05, -0.02, 0.0)),
        ("on_poster", None, (-0.35, 1.6, 0.1)),
    ]


@pytest.mark.parametrize(
    ("entry", "field", "says"),
    [
        (
            {**POSTER, "point_object_m": [0.0, 0.0, 0.01]},
            "[1].point_object_m",
            "10.0 mm from 'poster'",
        ),
        (
            {"name": "air", "point_world_m": [0.0, 1.0, 0.3]},
            "[1].point_world_m",
            "from the nearest surface",
        ),
        ({**POSTER, "object": "sofa"}, "[1].object", "no object named 'sofa'"),
        ({"name": "x", "object": "poster"}, "[1].point_object_m", "missing"),
        ({"name": "x"}, "[1].point_world_m", "missing"),
        (
            {**ON_POSTER, "point_object_m": [0, 0, 0]},
            "[1].point_world_m",
            "given with point_object_m",
        ),
        ({**POSTER, "name": "surface_3"}, "[1].name", "reserved"),
        ({**POSTER, "colour": "red"}, "[1].colour", "unknown key"),
    ],
)
def test_a_bad_listed_target_is_a_one_line_error_naming_its_field(
    entry: dict[str, Any], field: str, says: str
) -> None:
    with pytest.raises(ScenarioError) as error:
        _load([ON_POSTER, entry])
    text = str(error.value)
    assert f"scene.room.targets{field}: " in text and says in text
    assert "\n" not in text


def test_a_name_used_twice_is_refused() -> None:
    with pytest.raises(ScenarioError, match=r"targets\[1\]\.name: 'on_poster' is used twice"):
        _load([ON_POSTER, ON_POSTER])


def test_targets_as_is_surface_or_markers() -> None:
    doc = set_field(read_toml(PATH), "scene.room.targets_as", "stickers")
    with pytest.raises(ScenarioError, match=r"scene\.room\.targets_as: unknown value"):
        scenario_from_document(doc, "natural_field", directory=PATH.parent)
    spec = load_scenario("natural_field_markers", fast=True).scene.surface_targets
    assert spec is not None and spec.targets_as == "markers"
