"""Model 1, fixation with the neck, with real rendering."""

from __future__ import annotations

import numpy as np

from headsim.active.measurement import body_target
from headsim.active.model1 import measure_model1
from headsim.active.neck_servo import NeckServo
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))


def test_model1_fixates_with_the_neck_and_places_the_point_in_the_world() -> None:
    with HeadSim("default") as sim:
        sim.set_body_pose("marker_red", [0.15, 0.7, 0.35])
        m = measure_model1(sim, NeckServo(sim), RED)
        assert m.ok, m.status
        assert abs(m.details["neck_yaw_rad"]) > 0.1 and m.details["neck_pitch_rad"] > 0.1
        # Fixated on the bisector, in the plane of the optical axes.
        assert np.linalg.norm(m.truth_head_m[:2]) < 0.003
        assert m.error_pct_of_depth < 0.5
        np.testing.assert_allclose(m.estimate_world_m, m.truth_world_m, atol=0.005 * m.depth_m)
