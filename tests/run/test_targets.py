"""The scenario's marker targets (run/targets.py): found by colour where the body truly is."""

from __future__ import annotations

import numpy as np

from headsim.runs.targets import marker_target
from headsim.sim.simulator import HeadSim


def test_each_marker_target_finds_its_own_body_and_knows_where_it_is() -> None:
    with HeadSim("default") as sim:
        image = sim.render(1)
        seen = 0
        for body in ("marker_red", "marker_green", "marker_blue"):
            target = marker_target(body.removeprefix("marker_"), body)
            assert target.name == body.removeprefix("marker_")
            truth = target.truth_world(sim)
            np.testing.assert_array_equal(truth, sim.position(body))
            uv = sim.project(truth, 1)[0]
            found = target.detector(image)
            in_view = 0 <= uv[0] < image.shape[1] and 0 <= uv[1] < image.shape[0]
            assert found.found == in_view, body
            if found.found:
                seen += 1
                np.testing.assert_allclose(found.uv, uv, atol=0.5)
        assert seen >= 1
