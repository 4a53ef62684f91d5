"""``[scene.pursuit]``: the pursuit procedure's path, timing and gaze, checked where they enter."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import numpy as np
import pytest

from headsim.scenario.loading import load_scenario
from headsim.scenario.pursuit import PursuitSpec
from headsim.scenario.tables import ScenarioError

PURSUIT = """
description = "a pursuit"

[experiment]
procedure = "pursuit"

[scene.pursuit]
body = "marker_green"
duration_s = 2.0

[scene.pursuit.path]
kind = "waypoints"
points_world_m = [[-0.1, 1.0, 0.21], [0.1, 1.0, 0.21]]
speeds_m_s = [0.2]
windows_s = [[0.0, 0.5], [1.0, 2.0]]

[scene.pursuit.live]
frame_rate_hz = 20.0
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "pursuit.toml"
    path.write_text(textwrap.dedent(text))
    return path


def test_the_pursuit_table_becomes_a_checked_spec(tmp_path: Path) -> None:
    scenario = load_scenario(_write(tmp_path, PURSUIT))
    spec = scenario.scene.pursuit
    assert isinstance(spec, PursuitSpec)
    assert (spec.body, spec.kind, spec.duration_s) == ("marker_green", "waypoints", 2.0)
    assert spec.live.frame_rate_hz == 20.0
    np.testing.assert_allclose(spec.path.position(0.0), [-0.1, 1.0, 0.21], atol=1e-12)
    np.testing.assert_allclose(spec.path.position(0.5), [0.0, 1.0, 0.21], atol=1e-12)
    assert spec.visibility.visible(0.25) and not spec.visibility.visible(0.75)
    assert scenario.fixations == 40  # one step per camera frame: 2 s at 20 Hz


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("speeds_m_s = [0.2]", "speeds_m_s = [0.2, 0.3]"), "scene.pursuit.path.speeds_m_s: missing or wrong length"),
        (('kind = "waypoints"', 'kind = "orbit"'), "scene.pursuit.path.kind: unknown value 'orbit'"),
        (("windows_s = [[0.0, 0.5], [1.0, 2.0]]", "windows_s = [1.0]"), "scene.pursuit.path.windows_s: must be an array of pairs"),
    ],
    ids=["speeds", "kind", "windows"],
)  # fmt: skip
def test_a_bad_pursuit_field_is_named(
    tmp_path: Path, change: tuple[str, str], message: str
) -> None:
    path = _write(tmp_path, PURSUIT.replace(*change))
    with pytest.raises(ScenarioError, match=re.escape(f"{path}: {message}")):
        load_scenario(path)


JUMP = {
    "scene.pursuit.path": {
        "kind": "jump",
        "start_world_m": [0.0, 1.0, 0.21],
        "end_world_m": [0.1, 1.0, 0.25],
        "time_s": 0.2,
    }
}
WALK = {
    "scene.pursuit.path": {
        "kind": "random_walk",
        "start_world_m": [0.0, 1.0, 0.21],
        "max_speed_m_s": 0.3,
    }
}


def test_a_jump_holds_the_start_then_the_end() -> None:
    spec = load_scenario("pursuit", overrides=JUMP).scene.pursuit
    assert spec is not None and spec.kind == "jump"
    np.testing.assert_array_equal(spec.path.position(0.19), [0.0, 1.0, 0.21])
    np.testing.assert_array_equal(spec.path.position(0.2), [0.1, 1.0, 0.25])


def test_a_random_walk_takes_its_own_seed_else_the_scenario_s() -> None:
    def at_one_second(seed: int | None, scenario_seed: int = 0) -> np.ndarray:
        path = dict(WALK["scene.pursuit.path"], **({} if seed is None else {"seed": seed}))
        overrides = {"scene.pursuit.path": path}
        spec = load_scenario("pursuit", seed=scenario_seed, overrides=overrides).scene.pursuit
        assert spec is not None
        return spec.path.position(1.0)

    np.testing.assert_array_equal(at_one_second(None, 5), at_one_second(5, 0))
    assert not np.array_equal(at_one_second(None, 0), at_one_second(5, 0))


@pytest.mark.parametrize(
    ("path", "key", "message"),
    [
        (
            dict(JUMP["scene.pursuit.path"], time_s=-1.0),
            "time_s",
            "-1 is out of range (allowed: a number >= 0 and <= 3600 s)",
        ),
        (
            dict(JUMP["scene.pursuit.path"], end_world_m=[0.1, 1.0]),
            "end_world_m",
            "must be an array of 3 numbers",
        ),
        (
            dict(WALK["scene.pursuit.path"], seed=-3),
            "seed",
            "-3 is out of range (allowed: an integer from 0 to 4294967295)",
        ),
        (dict(WALK["scene.pursuit.path"], seed=1.5), "seed", "must be an integer"),
    ],
    ids=["jump time", "jump end", "seed range", "seed type"],
)
def test_a_bad_jump_or_walk_seed_is_named(path: dict[str, object], key: str, message: str) -> None:
    with pytest.raises(ScenarioError, match=re.escape(f"scene.pursuit.path.{key}: {message}")):
        load_scenario("pursuit", overrides={"scene.pursuit.path": path})
