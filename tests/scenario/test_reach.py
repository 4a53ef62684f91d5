"""The reach check: a target, corner, object or path point the head cannot fixate at all is
refused without rendering, naming why; one that only the start pose does not show is
accepted (the procedures scan for it), and random draws the check refuses are counted."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from headsim.geometry.kinematics import head_to_world
from headsim.geometry.sampling import sample_points_head
from headsim.scenario.loading import load_scenario
from headsim.scenario.reach import ReachHead, body_radius, model2_refusal, scene_occluders
from headsim.scenario.spec import REFUSAL_REASONS, STREAM_TARGETS
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
        # Far above the view: no eye angle shows it (the neck stays still for Model 2).
        "[0.0, 0.7, 1.0]",
        "scene.targets[0]: target at [0.000, 0.700, 1.000] m in H is not seen whole by camera 1 even "
        "where it fixates it (eye angle 0.075 rad): it lies above or below that view (allowed: "
        "targets that each camera sees whole at some eye angle with the neck still)",
    ),
    (
        # Straight behind the default scene's green marker, seen from camera 1.
        "[-0.0825, 0.015, 1.125]",
        "scene.targets[0]: target at [-0.083, 0.015, 1.125] m in H is hidden from camera 1 by "
        "marker_green (allowed: targets that both cameras see with nothing of the scene in front "
        "of them)",
    ),
]


@pytest.mark.parametrize(
    ("position", "message"), REACH, ids=["behind", "eye range", "out of every view", "occluded"]
)
def test_a_target_out_of_reach_is_refused_without_rendering(
    tmp_path: Path, position: str, message: str
) -> None:
    text = MINIMAL.replace("[0.02, 0.01, 0.6]", position)
    path = write_scenario(tmp_path, text)
    with pytest.raises(ScenarioError, match=re.escape(f"{path}: {message}")):
        load_scenario(path)


def test_a_target_only_the_start_pose_misses_is_accepted_at_the_edge_of_the_field(
    tmp_path: Path,
) -> None:
    # Camera 2 sees it at the start pose, camera 1 does not: the check before refused it;
    # both eyes can fixate it, so Model 2 scans the eyes for it.
    scenario = load_scenario(
        write_scenario(tmp_path, MINIMAL.replace("[0.02, 0.01, 0.6]", "[0.3, 0.0, 0.5]"))
    )
    a = scenario.scene.acceptance
    assert a is not None
    assert (a.within, a.listed, a.drawn, a.refused, a.accepted) == (None, 1, 0, {}, 1)
    assert a.outside_start_view == ("target_1",)
    # The middle of the field is not at the edge.
    inside = load_scenario(write_scenario(tmp_path, MINIMAL, "ok.toml")).scene.acceptance
    assert inside is not None and inside.outside_start_view == ()


ZOOM_BOX = """
description = "counting"
seed = 3

[head]
preset = "paper"

[cam1]
kx = 1669.66
ky = 1630.84

[cam2]
kx = 1700.92
ky = 1666.58

[experiment]
procedure = "model2"

[scene.random_targets]
count = 40
depth_m = [0.3, 1.4]
lateral = 0.9
vertical = 0.2
within = "reach"
"""


def test_refused_draws_are_counted_by_reason_as_the_reach_functions_count_them(
    tmp_path: Path,
) -> None:
    scenario = load_scenario(write_scenario(tmp_path, ZOOM_BOX))
    a = scenario.scene.acceptance
    assert a is not None
    # An independent count: the same seeded draws, each refused one drawn again,
    # through the reach functions themselves.
    s = scenario.settings
    head = ReachHead.of(s)
    occluders = scene_occluders("default", {}, "marker_red")
    radius = body_radius("marker_red")
    rng = np.random.default_rng([3, STREAM_TARGETS])

    def draw(n: int) -> np.ndarray:
        points = sample_points_head(rng, n, (-0.9, 0.9), (-0.2, 0.2), depth_range_m=(0.3, 1.4))
        return head_to_world(points, 0.0, 0.0, s.neck_d1_m, s.neck_a2_m)

    points = draw(40)
    counted: dict[str, int] = {}
    lo, hi = head.eye_range
    for k in range(40):
        while (refusal := model2_refusal(head, points[k], "target", radius, occluders)) is not None:
            counted[refusal.code] = counted.get(refusal.code, 0) + 1
            angles = head.model2_angles(head.to_head(points[k]))
            # Refused for the eye range exactly when an eye cannot turn far enough.
            assert (refusal.code == "eye_range") == (not all(lo <= x <= hi for x in angles))
            points[k] = draw(1)[0]
    assert a.refused == dict(sorted(counted.items(), key=lambda kv: (-kv[1], kv[0])))
    assert set(a.refused) <= set(REFUSAL_REASONS)
    # The box reaches beyond the eye range sideways and beyond the view vertically.
    assert a.refused["eye_range"] > 0 and a.refused["not_in_any_view"] > 0
    assert (a.within, a.listed, a.accepted) == ("reach", 0, 40)
    assert a.drawn == 40 + a.refused_total
    np.testing.assert_allclose([t.position_world_m for t in scenario.scene.targets], points)
    # Accepted: every one within the eye range; the start pose misses some of them.
    for t in scenario.scene.targets:
        angles = head.model2_angles(head.to_head(np.array(t.position_world_m)))
        assert all(lo <= alpha <= hi for alpha in angles)
    edge = {
        t.name
        for t in scenario.scene.targets
        if not head.in_start_view(np.array(t.position_world_m), radius)
    }
    assert set(a.outside_start_view) == edge and 0 < len(edge) < 40


def test_other_scenes_check_their_own_things(tmp_path: Path) -> None:
    board = 'description = "b"\n[experiment]\nprocedure = "chessboard"\n[scene.chessboard]\n'
    with pytest.raises(
        ScenarioError, match=r"scene.chessboard.corners: \[48\] has an index out of range"
    ):
        load_scenario(write_scenario(tmp_path, board + "corners = [48]\n"))
    with pytest.raises(ScenarioError, match=r"scene.chessboard: corner 0 at .* is behind"):
        load_scenario(write_scenario(tmp_path, board + "position_head_m = [0.0, 0.0, -1.0]\n"))
    # The chessboard procedure starts at the start pose: a corner out of its view is refused.
    with pytest.raises(
        ScenarioError,
        match=r"scene.chessboard: corner 0 at .* is not seen whole by camera 1 at the start pose",
    ):
        load_scenario(write_scenario(tmp_path, board + "position_head_m = [0.3, 0.0, 0.5]\n"))
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
        match=r"scene.targets: unknown key \(allowed: room, blocks, objects, random_objects\)",
    ):
        load_scenario(
            write_scenario(tmp_path, blocks + "[[scene.targets]]\nposition_head_m = [0, 0, 1]\n")
        )


WIDE_FIELD = """description = "16 random targets over the whole shared field at 1.3x focal"
[head]
preset = "ideal"
[cam1]
kx = 753.2
ky = 753.2
[cam2]
kx = 753.2
ky = 753.2
[experiment]
procedure = "model2"
[scene.random_targets]
count = 16
depth_m = [0.3, 1.5]
lateral = 0.6
vertical = 0.4
"""


def test_a_refused_random_target_says_how_to_have_it_drawn_again(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from headsim.cli import main

    path = tmp_path / "wide.toml"
    path.write_text(WIDE_FIELD)
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "scene.random_targets (target 1):" in err
    assert 'within = "reach" in [scene.random_targets], which draws each target' in err
    assert not (tmp_path / "out").exists()
    path.write_text(WIDE_FIELD + 'within = "reach"\n')
    redrawn = load_scenario(path)
    assert redrawn.scene.acceptance is not None and redrawn.scene.acceptance.refused_total > 0
    assert len(redrawn.scene.targets) == 16


def test_a_refused_listed_target_gets_no_redraw_hint(tmp_path: Path) -> None:
    path = write_scenario(tmp_path, MINIMAL.replace("[0.02, 0.01, 0.6]", "[0.6, 0.0, 0.3]"))
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert 'within = "reach"' not in str(caught.value)


def test_a_relative_object_seen_only_at_the_cross_points_fixations_is_accepted(
    tmp_path: Path,
) -> None:
    # The procedure reads objects in the four images at the cross point's two
    # fixations: one those images see whole is accepted though the start pose misses it.
    reference_head = np.array([0.06, 0.0, 0.6])
    text = (
        'description = "r"\n[head]\npreset = "paper"\n'
        '[experiment]\nprocedure = "relative_positioning"\n'
        "[scene.blocks]\nposition_head_m = [0.06, 0.0, 0.6]\n"
    )
    settings = load_scenario(write_scenario(tmp_path, text)).settings
    head = ReachHead.of(settings)
    fixations = head.model2_angles(reference_head)
    candidates = sample_points_head(
        np.random.default_rng(0), 4000, (-0.6, 0.6), (-0.1, 0.1), depth_range_m=(0.3, 1.5)
    )

    def seen(p: np.ndarray, eyes: tuple[float, ...]) -> bool:
        return all(head.in_view(p, k, eye) for k in (0, 1) for eye in eyes)

    only_fixations = next(p for p in candidates if seen(p, fixations) and not seen(p, (0.0,)))
    neither = next(p for p in candidates if not seen(p, fixations) and not seen(p, (0.0,)))

    def with_object(p: np.ndarray) -> Path:
        position = [float(v) for v in p]
        return write_scenario(
            tmp_path, text + f"[[scene.objects]]\nbody = 'object_1'\nposition_head_m = {position}\n"
        )

    scenario = load_scenario(with_object(only_fixations))
    assert [o.body for o in scenario.scene.objects] == ["object_1"]
    with pytest.raises(
        ScenarioError,
        match=r"scene.objects\[0\]: object_1 at .* is outside a camera's view at the start pose "
        r"and at the cross point's fixations \(allowed: objects that both cameras see",
    ):
        load_scenario(with_object(neither))
