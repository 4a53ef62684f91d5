"""The servos know nothing of the scene but their images: no "the target moved" from the
simulator.  A window where the last sight puts the target is a guess the next image
confirms or not; a target moved away is found again in a preview, one moved a little
is handled from the window.  Real rendering, the ideal head (no noise: a window's
pixels are the full frame's)."""

from __future__ import annotations

import ast
from pathlib import Path

import mujoco
import numpy as np
import pytest

from headsim.active.chessboard import chessboard_corner_target
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import Measurement, body_target
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.sim import names
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.settings import paper_head
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))
SOURCE = Path(__file__).resolve().parents[2] / "headsim"


class Kinds:
    """An event sink that keeps the kind of every image taken."""

    def __init__(self) -> None:
        self.kinds: list[ImageKind] = []

    def emit(self, event: object) -> None:
        if isinstance(event, ImageTaken):
            self.kinds.append(event.kind)


def _world(sim: HeadSim, p_head: list[float]) -> np.ndarray:
    return sim.transform_points(np.asarray(p_head, dtype=float), "head", "world")[0]


def _told(sim: HeadSim, p_world: np.ndarray) -> None:
    """Move the target as every procedure does (the simulator counts its placements)."""
    sim.set_body_pose("marker_red", p_world)


def _silent(sim: HeadSim, p_world: np.ndarray) -> None:
    """Move the target as the world would: nothing but the scene changes."""
    mocap = int(sim.model.body_mocapid[sim.model.body("marker_red").id])
    sim.data.mocap_pos[mocap] = p_world
    mujoco.mj_forward(sim.model, sim.data)


def _measure_then_move(move, far: bool) -> tuple[Measurement, list[ImageKind], EyeServo]:
    """Model 2 on the red marker, then on it moved (``far``: to the other side of the
    view and nearer; else 2 mm) by ``move``: the second measurement and its images."""
    sink = Kinds()
    with HeadSim("default", sink=sink) as sim:
        servo = EyeServo(sim)
        _told(sim, _world(sim, [0.08, -0.03, 0.9]))
        assert measure_model2(sim, servo, RED).ok
        sink.kinds.clear()
        move(sim, _world(sim, [-0.06, 0.04, 0.6] if far else [0.082, -0.03, 0.9]))
        return measure_model2(sim, servo, RED), sink.kinds, servo


@pytest.mark.parametrize("far", [True, False], ids=["far", "near"])
def test_the_servo_cannot_tell_whether_it_was_told_the_target_moved(far: bool) -> None:
    told, told_kinds, _ = _measure_then_move(_told, far)
    silent, silent_kinds, _ = _measure_then_move(_silent, far)
    assert told.ok and silent.ok
    assert told_kinds == silent_kinds
    np.testing.assert_array_equal(told.estimate_head_m, silent.estimate_head_m)
    assert told.error_pct_of_depth < 0.1 and silent.error_pct_of_depth < 0.1


def test_a_target_moved_far_is_found_again_in_a_preview() -> None:
    moved, kinds, servo = _measure_then_move(_told, far=True)
    # Camera 1 looks where it last saw the target (a window: nothing there), finds it in
    # a preview and takes the window it places of the same instant.
    assert kinds[:3] == [ImageKind.WINDOW, ImageKind.PREVIEW, ImageKind.RETAKE]
    assert servo.looker.counts.window_misses >= 1
    assert moved.ok and moved.error_pct_of_depth < 0.1
    np.testing.assert_allclose(moved.truth_head_m, [-0.06, 0.04, 0.6], atol=1e-12)
    assert moved.renders == len(kinds)


def test_a_target_moved_a_little_is_seen_in_the_old_window() -> None:
    moved, kinds, servo = _measure_then_move(_told, far=False)
    # No preview, no miss: every look is a window where the last sight put the target.
    assert ImageKind.PREVIEW not in kinds and ImageKind.RETAKE not in kinds
    assert kinds[0] is ImageKind.WINDOW and servo.looker.counts.window_misses == 0
    assert moved.ok and moved.error_pct_of_depth < 0.1
    np.testing.assert_allclose(moved.truth_head_m, [0.082, -0.03, 0.9], atol=1e-12)


def test_a_blob_much_smaller_than_last_seen_is_not_trusted_in_the_old_window() -> None:
    """The target moved along camera 1's line of sight, twice as far: its blob is where it
    was, well inside the old window, at a quarter of the area.  That window is a miss (it
    may show something else of the colour); the preview finds it, and the detection is
    the full frame's."""
    sink = Kinds()
    with HeadSim("default", sink=sink) as sim, HeadSim("default") as plain:
        servo = EyeServo(sim)
        p = _world(sim, [0.05, 0.02, 0.5])
        _told(sim, p)
        assert servo.run(1, RED.detector).converged  # a gain: windows from here on
        first = servo.observe(1, RED.detector)
        centre = sim.world_from_camera(1)[:3, 3]
        far = centre + 2.0 * (p - centre)
        _told(sim, far)
        sink.kinds.clear()
        seen = servo.observe(1, RED.detector)
        assert sink.kinds == [ImageKind.WINDOW, ImageKind.PREVIEW, ImageKind.RETAKE]
        assert servo.looker.counts.window_misses == 1
        assert seen.area_px == pytest.approx(first.area_px / 4, rel=0.1)
        _told(plain, far)
        plain.command_eye_steps(sim.eye_encoder_steps())
        plain.settle()
        whole = RED.detector(plain.render(1))
        assert seen.uv == pytest.approx(whole.uv, abs=1e-9)
        assert seen.uv == pytest.approx(first.uv, abs=0.5)  # where the old window expected


def test_the_neck_servo_finds_a_moved_target_from_its_images() -> None:
    """Model 1's servo fixates, the target moves a little, then far: the small move is
    fixated from windows where the last images put it, the far one found again in a
    preview after the old window missed; told or not, the same images."""
    runs = []
    for move in (_told, _silent):
        sink = Kinds()
        with HeadSim("default", sink=sink) as sim:
            servo = NeckServo(sim)
            # In the head frame of the start pose (the neck moves the head frame).
            start, near, far = (
                _world(sim, p)
                for p in ([0.03, 0.01, 0.7], [0.0302, 0.01, 0.7], [-0.08, -0.05, 0.9])
            )
            move(sim, start)
            assert servo.run(RED.detector).converged
            kinds = []
            for p_world in (near, far):
                sink.kinds.clear()
                move(sim, p_world)
                result = servo.run(RED.detector)
                assert result.converged and result.residual_px < 0.5
                kinds.append(list(sink.kinds))
            runs.append((kinds, servo.looker.counts.window_misses))
    (near, far), misses = runs[0]
    assert runs[1] == runs[0]
    assert ImageKind.PREVIEW not in near and near[0] is ImageKind.WINDOW
    assert far[:3] == [ImageKind.WINDOW, ImageKind.PREVIEW, ImageKind.RETAKE]
    assert misses >= 1


def test_a_board_moved_by_whole_squares_gives_the_corner_a_fresh_head_measures() -> None:
    """A chessboard's corners all look alike: after the board moved by exactly two squares,
    the place where the last fixation put corner 19 holds corner 17.  Each corner is read
    off the whole board, so the corner measured is corner 19, as a fresh head measures
    it."""
    shifted = np.array([0.06, 0.0, 0.0])  # two 30 mm squares along the board's rows
    target = chessboard_corner_target(19, (8, 6), 0.03)
    estimates: list[np.ndarray] = []
    for remembered in (True, False):
        with HeadSim("chessboard", paper_head()) as sim:
            base = sim.transform_points([-0.105, -0.075, 0.85], "head", "world")[0]
            sim.set_body_pose(names.CHESSBOARD, base)
            rows = sim.data.body(names.CHESSBOARD).xmat.reshape(3, 3)
            servo = EyeServo(sim)
            if remembered:
                assert measure_model2(sim, servo, target).ok
            sim.set_body_pose(names.CHESSBOARD, base + rows @ shifted)
            m = measure_model2(sim, servo, target)  # the fresh head: its first sight
            assert m.ok
            estimates.append(m.estimate_head_m)
    np.testing.assert_allclose(estimates[0], estimates[1], atol=1e-5)  # 0.01 mm


def _reads_placements(path: Path) -> bool:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return any(
        (isinstance(node, ast.Attribute) and node.attr == "placements")
        or (isinstance(node, ast.Constant) and node.value == "placements")
        for node in ast.walk(tree)
    )


def test_nothing_the_head_runs_reads_the_simulators_placements() -> None:
    # sim.placements counts the bodies the simulator moved: the truth of "the scene
    # changed", for recording only.  The servos, the live head and the envs decide
    # from their images.
    parts = ("active", "live", "envs", "vision")  # vision: the markerless correspondence too
    files = [p for part in parts for p in (SOURCE / part).rglob("*.py")]
    assert len(files) > 20
    assert [str(p.relative_to(SOURCE)) for p in files if _reads_placements(p)] == []
    assert _reads_placements(SOURCE / "sim" / "simulator.py")  # the check can see a read


#: Modules that read the scene's truth (where a surface target is, where the eyes
#: landed), for placing, scoring and recording: what the head runs never imports them.
TRUTH_MODULES = ("headsim.runs.landing", "headsim.scenario.surface_targets")


def _imports(path: Path) -> set[str]:
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return found


def test_no_servo_tracker_or_correspondence_imports_the_scene_truth() -> None:
    files = [p for part in ("active", "vision", "live") for p in (SOURCE / part).rglob("*.py")]
    assert len(files) > 20
    readers = [str(p.relative_to(SOURCE)) for p in files if _imports(p).intersection(TRUTH_MODULES)]
    assert readers == []
    # The check can see an import: the scorer's own module imports the placing one.
    assert TRUTH_MODULES[1] in _imports(SOURCE / "runs" / "landing.py")


#: Where a scene's state is read: the simulator (its model, data, bodies' poses) and the
#: live head's scoring truth (the target's path point, the scored point's offset).
SCENE_STATE = frozenset(
    {
        "sim",
        "data",
        "model",
        "mocap_pos",
        "xpos",
        "placements",
        "target_truth",
        "point_offset_m",
        "truth_target_world_m",
        "true_joints",
    }
)


def _scene_reads(node: ast.AST) -> set[str]:
    """The names and attributes of :data:`SCENE_STATE` that ``node`` reads."""
    found = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Attribute) and sub.attr in SCENE_STATE:
            found.add(sub.attr)
        elif isinstance(sub, ast.Name) and sub.id in SCENE_STATE:
            found.add(sub.id)
    return found


def _function(path: Path, name: str) -> ast.AST:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == name)


def test_the_tracker_and_the_correspondence_see_only_images() -> None:
    # The markerless pair (camera 1's tracker, camera 2's correspondence) and the live
    # pursuit's per-camera detection take images, pixels and the belief's band: no
    # simulator, no pose of a body, no scoring truth.
    for module in ("active/markerless.py", "vision/correspondence.py"):
        tree = ast.parse((SOURCE / module).read_text(encoding="utf-8"))
        assert _scene_reads(tree) == set(), module
    assert _scene_reads(_function(SOURCE / "live" / "gaze.py", "detect")) == set()
    # The check can see a read: the textured pursuit's click, truth (through the head's
    # channel) for placing it.
    clicked = _function(SOURCE / "procedures" / "pursuit.py", "_click_object")
    assert {"model", "data", "xpos"} <= _scene_reads(clicked)
