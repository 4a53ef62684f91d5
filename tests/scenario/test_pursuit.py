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
