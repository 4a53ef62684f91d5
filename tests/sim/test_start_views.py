"""A fresh simulator's views from the head's settings alone: the start pose and turned eyes."""

from __future__ import annotations

import numpy as np

from headsim.sim.settings import paper_head
from headsim.sim.simulator import HeadSim, effective_initial_direction, start_views


def test_start_views_with_eye_angles_are_a_simulators_views_at_those_angles() -> None:
    settings = paper_head()
    angles = (0.12, -0.05)
    with HeadSim("blocks", settings) as sim:
        expected = sim.stereo_views(angles)
        directions = [sim.effective_initial_direction(c, 300.0) for c in (1, 2)]
    got = start_views(settings, "blocks", angles)
    assert len(got) == 3
    for view, want in zip(got, expected, strict=True):
        for pose, wanted in zip(view.camera_from_world, want.camera_from_world, strict=True):
            np.testing.assert_allclose(pose, wanted, atol=1e-12)
    # Turned eyes move the cameras: the turned views are not the start pose's.
    assert not np.allclose(got[1].camera_from_world[0], got[0].camera_from_world[0], atol=1e-3)
    assert [effective_initial_direction(settings, i, 300.0) for i in (0, 1)] == directions
