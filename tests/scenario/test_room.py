"""``[scene.room]``: the room read from the scenario and drawn from its seed, its bad
values refused by name, and its objects hiding targets from the reach check."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.scenario.loading import load_scenario, scenario_from_document
from headsim.scenario.tables import ScenarioError


def _doc(room: dict, targets: dict | None = None) -> dict:
    return {
        "description": "a room",
        "experiment": {"procedure": "model2"},
        "scene": {
            "room": room,
            "random_targets": targets or {"count": 2, "depth_m": [0.6, 1.2]},
        },
    }


def test_natural_field_has_its_room_and_clutter_from_the_seed() -> None:
    room = load_scenario("natural_field", fast=True).scene.room
    assert room is not None and room.surface == "pink" and not room.light.shadows
    listed = [o for o in room.objects if not o.name.startswith("clutter_")]
    clutter = [o for o in room.objects if o.name.startswith("clutter_")]
    assert [o.name for o in listed] == [
        "poster",
        "box_low",
        "books",
        "mug",
        "cereal_box",
        "ball",
        "book_stand",
    ] and len(clutter) == 12
    for obj in clutter:
        half_height = (
            obj.size_m[0] if obj.shape == "sphere" else obj.size_m[2 if obj.shape == "box" else 1]
        )
        assert obj.pos_world_m[2] == pytest.approx(room.table_top_z_m + half_height, abs=1e-12)
        assert 0.3 <= obj.pos_world_m[1] <= 2.0
        assert room.table_x_m[0] < obj.pos_world_m[0] < room.table_x_m[1]
    again = load_scenario("natural_field", fast=True).scene.room
    assert again == room
    other = load_scenario("natural_field", fast=True, seed=1).scene.room
    assert other is not None and other.objects[6:] != room.objects[6:]


@pytest.mark.parametrize(
    ("room", "field", "allowed"),
    [
        ({"surface": "plaid"}, "scene.room.surface", "pink, grating, low, repetitive"),
        ({"clutter": 41}, "scene.room.clutter", "from 0 to 40"),
        ({"clutter_depth_m": [1.0, 0.5]}, "scene.room.clutter_depth_m", "near < far"),
        ({"light": {"direction_world": [0, 0, 0]}}, "direction_world", "!= 0"),
        ({"light": {"shadows": 1}}, "scene.room.light.shadows", "true, false"),
        ({"objects": [{"shape": "torus"}]}, r"objects\[0\]\.shape", "box, cylinder"),
        (
            {"objects": [{"shape": "sphere", "size_m": [0, 0, 0], "pos_world_m": [0, 1, 0]}]},
            r"objects\[0\]\.size_m",
            "radius",
        ),
        (
            {
                "objects": [
                    {
                        "name": "floor",
                        "shape": "sphere",
                        "size_m": [0.1, 0, 0],
                        "pos_world_m": [0, 1, 0],
                    }
                ]
            },
            r"objects\[0\]\.name",
            "not a body of the scenes",
        ),
        ({"lamp": 1}, "scene.room.lamp", "unknown key"),
        ({"targets": 201}, "scene.room.targets", "from 0 to 200"),
        ({"targets": 2, "targets_depth_m": [1.5, 0.5]}, "scene.room.targets_depth_m", "near < far"),
        ({"targets": 2, "targets_lateral": 0}, "scene.room.targets_lateral", "> 0"),
        ({"targets": 2, "band_px": 0.5}, "scene.room.band_px", ">= 1"),
        ({"targets": 2, "click_error_px": -1}, "scene.room.click_error_px", ">= 0"),
        ({"table_top_z_m": 3.0}, "scene.room.table_top_z_m", "< 2"),
    ],
)
def test_a_bad_room_value_is_refused_naming_its_key(room: dict, field: str, allowed: str) -> None:
    with pytest.raises(ScenarioError, match=field) as caught:
        scenario_from_document(_doc(room), "room")
    assert allowed in str(caught.value) and "\n" not in str(caught.value)


def test_a_panel_hiding_half_the_box_refuses_the_draws_behind_it_by_cause() -> None:
    """A panel 0.5 m deep covering x < 0 in front of the head: every random target
    behind it is hidden from a camera and drawn again, counted as occluded."""
    panel = {
        "name": "screen", "shape": "plane", "size_m": [0.6, 0.6, 0.0],
        "pos_world_m": [-0.6, 0.5, 0.2], "pitch_rad": math.pi / 2, "texture": "low",
    }  # fmt: skip
    targets = {"count": 8, "depth_m": [0.8, 1.2], "lateral": 0.2, "vertical": 0.05}
    scenario = scenario_from_document(_doc({"clutter": 0, "objects": [panel]}, targets), "room")
    acceptance = scenario.scene.acceptance
    assert acceptance is not None and acceptance.refused.get("occluded", 0) > 0
    assert acceptance.drawn == 8 + acceptance.refused_total
    for target in scenario.scene.targets:
        # Kept only where camera 1 (x = -75 mm, y about 0) sees past the panel's edge
        # at x = 0, y = 0.5 (5 mm for the eyes' exact place).
        x, y = target.position_world_m[0], target.position_world_m[1]
        assert x > 0.075 * (y - 0.5) / 0.5 - 0.005
    without = scenario_from_document(_doc({"clutter": 0}, targets), "room")
    assert without.scene.acceptance is not None
    assert without.scene.acceptance.refused.get("occluded", 0) == 0
    assert np.isfinite([t.position_world_m for t in without.scene.targets]).all()
