"""The scene tables: random targets are drawn from the seed inside their spec."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from headsim.scenario.loading import load_scenario

from .helpers import MINIMAL, write_scenario


def test_random_targets_are_drawn_inside_their_spec(tmp_path: Path) -> None:
    text = (
        MINIMAL
        + "[scene.random_targets]\ncount = 50\ndepth_m = [0.5, 0.8]\nlateral = 0.1\nvertical = 0.05\n"
    )
    scenario = load_scenario(write_scenario(tmp_path, text))
    from headsim.geometry.kinematics import world_to_head

    s = scenario.settings
    points = np.array(
        [t.position_world_m for t in scenario.scene.targets if t.name.startswith("random")]
    )
    head = world_to_head(points, 0.0, 0.0, s.neck_d1_m, s.neck_a2_m)
    assert len(points) == 50
    assert np.all((head[:, 2] >= 0.5) & (head[:, 2] <= 0.8))
    assert np.all(np.abs(head[:, 0] / head[:, 2]) <= 0.1)
    assert np.all(np.abs(head[:, 1] / head[:, 2]) <= 0.05)
