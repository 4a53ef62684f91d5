"""The landing truth in natural_field's rendered room: an eye servoed onto a marker among
the textured clutter looks at it, by its goal ray cast at the true pose; a goal beside
it lands on the room.  Real rendering, the real servo and detector."""

from __future__ import annotations

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.runs.landing import fixation_error, landing
from headsim.scenario.loading import load_scenario
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector


def test_an_eye_servoed_onto_a_marker_in_the_room_lands_on_it() -> None:
    room = load_scenario("natural_field", fast=True).scene.room
    assert room is not None and len(room.objects) > 10
    with HeadSim("default", HeadSettings(), room=room) as sim:
        target = sim.transform_points(np.array([0.06, 0.02, 0.9]), "head", "world")[0]
        sim.set_body_pose("marker_red", target)
        result = EyeServo(sim).run(1, MarkerDetector("red"))
        assert result.converged and result.uv is not None
        # The goal pixel: the servo's goal column, on the row where the image shows it.
        goal = (sim.camera_settings(1).image_centre[0], result.uv[1])
        found = landing(sim, 1, goal)
        assert found.body == "marker_red"
        assert found.point_world_m is not None
        error = fixation_error(found.origin_world_m, found.direction_world, None, target)
        # Within the servo's 0.1 px at about 580 px: about 0.01 degree.
        assert error.angle_deg < 0.02
        assert np.linalg.norm(found.point_world_m - target) < 0.0041  # on the 4 mm ball
        beside = landing(sim, 1, (goal[0] + 25.0, goal[1]))
        names = {o.name for o in (*room.surfaces(), *room.objects)}
        assert beside.body in names and beside.distance_m > found.distance_m
