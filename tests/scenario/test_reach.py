"""The reach check: a target, corner, object or path point the head cannot fixate from its start pose is refused without rendering, naming why."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from headsim.scenario.loading import load_scenario
from headsim.scenario.tables import ScenarioError

from .helpers import MINIMAL, write_scenario

REACH = [
    (
        "[0.0, 0.0, -0.3]",
        "scene.targets[0]: target at [0.000, 0.000, -0.300] m in H is behind or too close to the head "
        "(allowed: z_h from 0.1 to 10 m in front of the head)",
    ),
    (
        "[0.6, 0.0, 0.3]",
        "scene.targets[0]: target at [0.600, 0.000, 0.300] m in H needs an eye angle of 1.153 rad for "
        "camera 1 to fixate it (allowed: targets that both eyes fixate within the eye range [-0.7, 0.7] rad)",
    ),
    (
        "[0.0, 0.7, 1.0]",
        "scene.targets[0]: target at [0.000, 0.700, 1.000] m in H is not seen whole by camera 1 at the "
        "start pose (allowed: a target that both cameras see whole with neck and eyes at 0)",
    ),
    (
        # Camera 2 sees it, camera 1 does not: the procedure could not start step 1.
        "[0.3, 0.0, 0.5]",
        "scene.targets[0]: target at [0.300, 0.000, 0.500] m in H is not seen whole by camera 1 at the "
        "start pose (allowed: a target that both cameras see whole with neck and eyes at 0)",
    ),
]


@pytest.mark.parametrize(
    ("position", "message"), REACH, ids=["behind", "eye range", "out of view", "one camera only"]
)
def test_a_target_out_of_reach_is_refused_without_rendering(
    tmp_path: Path, position: str, message: str
) -> None:
    text = MINIMAL.replace("[0.02, 0.01, 0.6]", position)
    path = write_scenario(tmp_path, text)
    with pytest.raises(ScenarioError, match=re.escape(f"{path}: {message}")):
        load_scenario(path)


def test_other_scenes_check_their_own_things(tmp_path: Path) -> None:
    board = 'description = "b"\n[experiment]\nprocedure = "chessboard"\n[scene.chessboard]\n'
    with pytest.raises(
        ScenarioError, match=r"scene.chessboard.corners: \[48\] has an index out of range"
    ):
        load_scenario(write_scenario(tmp_path, board + "corners = [48]\n"))
    with pytest.raises(ScenarioError, match=r"scene.chessboard: corner 0 at .* is behind"):
        load_scenario(write_scenario(tmp_path, board + "position_head_m = [0.0, 0.0, -1.0]\n"))
    with pytest.raises(
        ScenarioError,
        match=r"scene.chessboard.position_world_m: given together with position_head_m",
    ):
        load_scenario(
            write_scenario(
                tmp_path, board + "position_head_m = [0, 0, 1]\nposition_world_m = [0, 1, 0]\n"
            )
        )
    track = (
        'description = "t"\n[experiment]\nprocedure = "tracking"\n[scene.moving_target]\n'
        "steps = 3\nduration_s = 1.0\n"
    )
    with pytest.raises(
        ScenarioError,
        match=r"scene.moving_target: the target at t = 1 s at .* needs a neck yaw of -2.783 rad",
    ):
        load_scenario(
            write_scenario(
                tmp_path, track + "waypoints_world_m = [[0.3, 0.8, 0.2], [0.3, -0.8, 0.2]]\n"
            )
        )
    with pytest.raises(ScenarioError, match=r"scene.moving_target.waypoints_head_m: missing"):
        load_scenario(write_scenario(tmp_path, track))
    blocks = 'description = "r"\n[experiment]\nprocedure = "relative_positioning"\n'
    with pytest.raises(ScenarioError, match=r"scene.objects\[1\].body: 'object_1' is placed twice"):
        load_scenario(
            write_scenario(
                tmp_path,
                blocks + "[[scene.objects]]\nbody = 'object_1'\nposition_head_m = [0, 0, 1]\n" * 2,
            )
        )
    with pytest.raises(
        ScenarioError,
        match=r"scene.targets: unknown key \(allowed: blocks, objects, random_objects\)",
    ):
        load_scenario(
            write_scenario(tmp_path, blocks + "[[scene.targets]]\nposition_head_m = [0, 0, 1]\n")
        )
