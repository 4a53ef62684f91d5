"""The loader's reach check: every listed target, chessboard corner, object and path
point of a scenario that the head cannot fixate (:mod:`headsim.scenario.reach`) is
refused, naming the field and why.  Geometry only, no rendering.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from headsim.procedures.contract import get
from headsim.scenario.occlusion import scene_model, scene_occluders
from headsim.scenario.reach import (
    ReachHead,
    Refusal,
    body_radius,
    depth_refusal,
    fmt_point,
    model1_refusal,
    model2_refusal,
    target_refusal,
)
from headsim.scenario.spec import (
    CHESSBOARD_PATTERN,
    CHESSBOARD_SQUARE_M,
    Placement,
    Scenario,
    corner_count,
)
from headsim.scenario.tables import Context, TargetRefused
from headsim.sim import names

#: What a refused random target's message adds: how to keep the box and still run.
REDRAW_HINT = (
    'or within = "reach" in [scene.random_targets], which draws each target the head '
    "cannot fixate again from the same box (counted in results.json)"
)


def _raise(ctx: Context, source: str, refusal: Refusal | None, *, drawn: bool = False) -> None:
    """Refuse the scenario for ``refusal``, if any; ``drawn``: a random target of a box
    drawn without ``within = "reach"``, whose message says how to have it drawn again."""
    if refusal is not None:
        allowed = f"{refusal.allowed}; {REDRAW_HINT}" if drawn else refusal.allowed
        raise TargetRefused(
            ctx.source, ctx.field_name(source), refusal.message, allowed, refusal.code
        )


def _check_in_front(ctx: Context, source: str, p_head: np.ndarray, what: str) -> None:
    _raise(ctx, source, depth_refusal(p_head, what))


def _chessboard_corners_world(placement: Placement, corners: tuple[int, ...] | None) -> np.ndarray:
    """World positions of the chosen inner corners of a board placed at ``placement``."""
    model = scene_model("chessboard")
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.body(names.CHESSBOARD).quat)
    columns = CHESSBOARD_PATTERN[0]
    indices = range(corner_count()) if corners is None else corners
    local = np.array(
        [
            [(k % columns) * CHESSBOARD_SQUARE_M, (k // columns) * CHESSBOARD_SQUARE_M, 0.0]
            for k in indices
        ]
    )
    return np.asarray(placement.position_world_m) + local @ rotation.reshape(3, 3).T


def target_refusals(
    head: ReachHead, reach: str, scene: str, targets: Sequence[tuple[str, np.ndarray]]
) -> list[Refusal | None]:
    """Why ``reach`` (a procedure's ``Procedure.reach``) cannot measure each of ``targets``
    (body, position in W, m) in turn (None: it can), in ``scene`` as the earlier accepted
    targets left it."""
    placed: dict[str, np.ndarray] = {}
    refusals: list[Refusal | None] = []
    for body, p in targets:
        occluders = scene_occluders(scene, placed, body)
        refusal = target_refusal(head, reach, p, "target", body_radius(body), occluders)
        refusals.append(refusal)
        if refusal is None:
            placed[body] = p
    return refusals


def check_reach(ctx: Context, scenario: Scenario) -> None:
    head = ReachHead.of(scenario.settings)
    scene = scenario.scene
    procedure = scenario.experiment.procedure
    acceptance = scene.acceptance
    # Random targets follow the listed ones; "box" keeps every draw as drawn.
    first_drawn = None if acceptance is None or acceptance.within != "box" else acceptance.listed
    listed = [(t.body, np.array(t.position_world_m)) for t in scene.targets]
    refusals = target_refusals(head, get(procedure).reach, scene.scene, listed)
    for index, (target, refusal) in enumerate(zip(scene.targets, refusals, strict=True)):
        drawn = first_drawn is not None and index >= first_drawn
        _raise(ctx, target.source, refusal, drawn=drawn)
    if scene.chessboard is not None:
        indices = range(corner_count()) if scene.corners is None else scene.corners
        for k, p in zip(
            indices, _chessboard_corners_world(scene.chessboard, scene.corners), strict=True
        ):
            refusal = model2_refusal(head, p, f"corner {k}", start_view=True)
            _raise(ctx, scene.chessboard.source, refusal)
    if scene.blocks is not None:
        p = np.array(scene.blocks.position_world_m)
        _raise(ctx, scene.blocks.source, model2_refusal(head, p, "cross point", start_view=True))
        # The procedure reads each object in the four images at the cross point's two
        # fixations (both eyes at alpha1, then at alpha2).
        fixations = head.model2_angles(head.to_head(p))
        for placement in scene.objects:
            p = head.to_head(np.array(placement.position_world_m))
            _check_in_front(ctx, placement.source, p, placement.name)
            at_start = head.in_view(p, 0) and head.in_view(p, 1)
            at_fixations = all(head.in_view(p, k, eye) for k in (0, 1) for eye in fixations)
            if not (at_start or at_fixations):
                raise TargetRefused(
                    ctx.source,
                    ctx.field_name(placement.source),
                    f"{placement.name} at {fmt_point(p)} m in H is outside a camera's view at "
                    "the start pose and at the cross point's fixations",
                    "objects that both cameras see with neck and eyes at 0, or in all four "
                    "images at the cross point's fixations",
                    "not_in_any_view",
                )
    if scene.pursuit is not None:
        pursuit = scene.pursuit
        first = True
        for t in pursuit.sample_times():
            if not pursuit.visibility.visible(float(t)):
                continue
            refusal = model1_refusal(
                head, pursuit.path.position(float(t)), f"the target at t = {t:g} s", first
            )
            _raise(ctx, "scene.pursuit.path", refusal)
            first = False
    if scene.moving is not None:
        moving = scene.moving
        for k, t in enumerate(moving.times_s):
            refusal = model1_refusal(
                head,
                moving.position(float(t)),
                f"the target at t = {t:g} s",
                k == 0,
                body_radius(moving.body),
            )
            _raise(ctx, "scene.moving_target", refusal)


__all__ = ["check_reach", "target_refusals"]
