"""The scene tables: ``[scene]`` with its targets and random layouts, and what every
procedure's own scene tables read with (positions, random points).

Positions are metres in H at the start pose (``position_head_m``: neck and
eyes at 0) or in W (``position_world_m``); random layouts are drawn with the
one sampler (:func:`headsim.geometry.sampling.sample_points_head`) from the
scenario's seed, one stream per use (``STREAM_*``).
"""

from __future__ import annotations

from collections.abc import Callable
from contextvars import ContextVar
from dataclasses import replace
from typing import Any

import numpy as np

from headsim.geometry.sampling import sample_points_head
from headsim.procedures.contract import get, procedures
from headsim.scenario.pursuit import read_pursuit
from headsim.scenario.reach import (
    Occluder,
    ReachHead,
    body_radius,
    scene_model,
    scene_occluders,
    target_refusal,
)
from headsim.scenario.room import ROOM_HAS_TARGETS, ROOM_OCCLUDERS, read_room, room_occluders
from headsim.scenario.schema import check_depth_range
from headsim.scenario.spec import (
    CALIBRATION_DEPTH,
    MARKER_BODIES,
    MAX_DEPTH_M,
    STREAM_TARGETS,
    Placement,
    SceneSpec,
    TargetAcceptance,
)
from headsim.scenario.tables import MISSING, Context, Table
from headsim.sim import names
from headsim.sim.declared import Choice, Section, Setting, Text
from headsim.sim.model import neck_of
from headsim.sim.settings import HeadSettings

_M = MAX_DEPTH_M
#: A position's keys (:func:`read_position`): in H at the start pose, or in W.
POSITION = (
    Setting("position_head_m", None, -_M, _M, "m", "Position in H at the start pose (neck and eyes at 0), m; or `position_world_m`.", count=3, optional=True),
    Setting("position_world_m", None, -_M, _M, "m", "Position in W, m; or `position_head_m`.", count=3, optional=True),
)  # fmt: skip


def position_of(what: str) -> tuple[Setting, ...]:
    """:data:`POSITION`, its meanings saying whose position it is."""
    return tuple(
        replace(d, meaning=f"{what}: {d.meaning[0].lower()}{d.meaning[1:]}") for d in POSITION
    )


#: A random box's keys (``[scene.random_*]``, :func:`random_points_head`).
DEPTH = replace(CALIBRATION_DEPTH, default=(0.5, 1.2), meaning="Depth range z_h of the drawn points in H, m.")  # fmt: skip
LATERAL = Setting("lateral", 0.12, 0.0, 1.0, "(|x_h / z_h|)", "Largest |x_h / z_h| of a drawn point (half the horizontal field, as a ratio).")  # fmt: skip
VERTICAL = Setting("vertical", 0.06, 0.0, 1.0, "(|y_h / z_h|)", "Largest |y_h / z_h| of a drawn point.")  # fmt: skip
RANDOM_BOX = (DEPTH, LATERAL, VERTICAL)
_BODY = Choice("body", tuple(MARKER_BODIES), names.MARKERS[0], "The marker body that stands for the target.")  # fmt: skip
_NAME = Text("name", None, "The target's name, unique (default `target_N`).", max_length=60, derived=True)  # fmt: skip
TARGETS = Section("scene.targets", "Fixed targets (model2, model1; for calibration: optional check targets).", (_NAME, _BODY, *POSITION), many=1000)  # fmt: skip
_COUNT = Setting("count", None, 1, 1000, "", "Number of random targets.", integer=True, required=True)  # fmt: skip
_WITHIN = Choice("within", ("box", "reach"), "box", "`box` refuses a drawn point out of reach and draws again one the scene hides; `reach` draws any refused point again (each redraw counted).")  # fmt: skip
RANDOM_TARGETS = Section("scene.random_targets", "More targets drawn from the seed, named `random_N`.", (_COUNT, replace(_BODY, meaning="The marker body of every random target."), _WITHIN, *RANDOM_BOX))  # fmt: skip
#: ``[scene]``'s shared tables, as the key reference lists them.
SECTIONS = (Section("scene", "What the procedure measures and where it is."), TARGETS, RANDOM_TARGETS)  # fmt: skip


def read_position(table: Table, settings: HeadSettings, default: Any = MISSING) -> np.ndarray:
    """``position_head_m`` (H at the start pose) or ``position_world_m``, as a world point."""
    in_head, in_world = (table.setting(d) for d in POSITION)
    allowed = "position_head_m = [x, y, z] (H at the start pose) or position_world_m, not both"
    if in_head is not None and in_world is not None:
        raise table.fail("position_world_m", "given together with position_head_m", allowed)
    if in_head is not None:
        return start_head_to_world(settings, np.array(in_head))
    if in_world is not None:
        return np.array(in_world)
    if default is MISSING:
        raise table.fail("position_head_m", "missing", allowed)
    return np.asarray(default, dtype=float)


def start_head_to_world(settings: HeadSettings, points_head: np.ndarray) -> np.ndarray:
    """Points (N, 3) in H at the start pose (neck and eyes at 0) in W, m."""
    neck = neck_of(settings.head)
    return neck.head_to_world(points_head, 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)


def random_points_head(table: Table, count: int, rng: np.random.Generator) -> np.ndarray:
    """Points (count, 3) in H drawn like ``calibration_layout``: depth, then angles."""
    near, far = check_depth_range(table, table.setting(DEPTH))
    lateral, vertical = table.setting(LATERAL), table.setting(VERTICAL)
    return sample_points_head(
        rng, count, (-lateral, lateral), (-vertical, vertical), depth_range_m=(near, far)
    )


def tuple3(p: np.ndarray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))


#: Draws per random target before ``within = "reach"`` gives up on the box.
MAX_DRAWS = 200
#: What ``within = "box"`` draws again: a draw that the scene's other markers happen to
#: hide (chance, not the box's fault: every seed must load).  Any other refusal says
#: that the box reaches beyond the head, and the loader refuses the box for it.
BOX_REDRAWN = frozenset({"occluded"})


def _redraw_out_of_reach(
    table: Table,
    settings: HeadSettings,
    procedure: str,
    body: str,
    points_world: np.ndarray,
    rng: np.random.Generator,
    occluders: tuple[Occluder, ...],
    redrawn: frozenset[str] | None = None,
) -> tuple[np.ndarray, dict[str, int]]:
    """Points drawn again from the same box until the reach check accepts each (bounded),
    and how many draws it refused, by reason code, most common first.  ``redrawn``: the
    reason codes drawn again (None: all); a draw refused for another is kept as drawn,
    for the loader's reach check to refuse."""
    head = ReachHead.of(settings)
    radius = body_radius(body)
    refused: dict[str, int] = {}
    points_world = np.array(points_world)
    for k in range(len(points_world)):
        for _ in range(MAX_DRAWS):
            refusal = target_refusal(
                head, get(procedure).reach, points_world[k], "target", radius, occluders
            )
            if refusal is None or (redrawn is not None and refusal.code not in redrawn):
                break
            refused[refusal.code] = refused.get(refusal.code, 0) + 1
            points_world[k] = start_head_to_world(settings, random_points_head(table, 1, rng))[0]
        else:
            raise table.fail(
                "within",
                f"no point of the box within the head's reach in {MAX_DRAWS} draws "
                f"(target {k + 1})",
                "a depth_m, lateral and vertical box that overlaps what the eyes can fixate",
            )
    return points_world, dict(sorted(refused.items(), key=lambda kv: (-kv[1], kv[0])))


def _read_targets(
    scene: Table, settings: HeadSettings, seed: int, required: bool, procedure: str = "model2"
) -> tuple[tuple[Placement, ...], TargetAcceptance]:
    """``[[scene.targets]]`` and ``[scene.random_targets]``: markers to measure, in turn,
    and how they were accepted (the loader's reach check refuses a listed one it cannot
    fixate; ``within = "reach"`` draws a refused random one again, ``"box"`` one that the
    scene hides, each counted)."""
    targets = []
    for k, table in enumerate(scene.sections(TARGETS)):
        name = table.setting(_NAME, f"target_{k + 1}")
        body = table.setting(_BODY)
        position = read_position(table, settings)
        table.done()
        targets.append(Placement(name, body, tuple3(position), table.path))
    listed = len(targets)
    random_table = scene.section(RANDOM_TARGETS)
    within: str | None = None
    drawn = 0
    refused: dict[str, int] = {}
    if random_table is not None:
        count = random_table.setting(_COUNT)
        body = random_table.setting(_BODY)
        within = random_table.setting(_WITHIN)
        rng = np.random.default_rng([seed, STREAM_TARGETS])
        points = start_head_to_world(settings, random_points_head(random_table, count, rng))
        # What can hide them: the scene as the listed targets leave it.
        placed = {t.body: np.array(t.position_world_m) for t in targets}
        occluders = scene_occluders(get(procedure).scene, placed, body) + ROOM_OCCLUDERS.get()
        points, refused = _redraw_out_of_reach(
            random_table,
            settings,
            procedure,
            body,
            points,
            rng,
            occluders,
            None if within == "reach" else BOX_REDRAWN,
        )
        drawn = count + sum(refused.values())
        random_table.done()
        targets += [
            Placement(f"random_{k + 1}", body, tuple3(p), f"{random_table.path} (target {k + 1})")
            for k, p in enumerate(points)
        ]
    if required and not targets and not ROOM_HAS_TARGETS.get():
        raise scene.fail(
            "targets", "no target to measure", "[[scene.targets]] entries or [scene.random_targets]"
        )
    seen: set[str] = set()
    for placement in targets:
        if placement.name in seen:
            raise scene.ctx.error(
                f"{placement.source}.name", f"{placement.name!r} is used twice", "unique names"
            )
        seen.add(placement.name)
    head = ReachHead.of(settings)
    acceptance = TargetAcceptance(
        within=within,
        listed=listed,
        drawn=drawn,
        refused=refused,
        accepted=len(targets),
        outside_start_view=tuple(
            t.name
            for t in targets
            if not head.in_start_view(np.array(t.position_world_m), body_radius(t.body))
        ),
    )
    return tuple(targets), acceptance


def default_position(scene: str, body: str) -> np.ndarray:
    """Where ``body`` stands in ``scene``'s model, W, m."""
    model = scene_model(scene)
    return np.array(model.body(body).pos, dtype=float)


#: The names of the room's objects while ``[scene]`` is read (a pursuit may move one).
ROOM_OBJECTS: ContextVar[tuple[str, ...]] = ContextVar("room_objects", default=())


def read_scene(
    doc: Table, ctx: Context, procedure: str, settings: HeadSettings, seed: int
) -> SceneSpec:
    """``[scene]``: what the procedure measures, and where it is."""
    found = get(procedure)
    table = doc.table("scene") or Table({}, "scene", ctx)
    room, surface_targets = read_room(table, seed)
    if surface_targets is not None and not found.markerless:
        measuring = [p.name for p in procedures() if p.markerless]
        raise ctx.error(
            "scene.room.targets",
            f"markerless targets are not measured by the {procedure} procedure",
            f"procedure = {' or '.join(measuring)}, or targets = 0",
        )
    # The room's surfaces and clutter can hide the procedure's targets.
    token = ROOM_OCCLUDERS.set(() if room is None else room_occluders(room))
    has_targets = ROOM_HAS_TARGETS.set(surface_targets is not None)
    objects = ROOM_OBJECTS.set(() if room is None else tuple(o.name for o in room.objects))
    try:
        read = found.read_scene
        spec = SceneSpec(scene=found.scene) if read is None else read(table, ctx, settings, seed)
    finally:
        ROOM_OCCLUDERS.reset(token)
        ROOM_HAS_TARGETS.reset(has_targets)
        ROOM_OBJECTS.reset(objects)
    table.done()
    return spec if room is None else replace(spec, room=room, surface_targets=surface_targets)


#: ``read_scene(scene_table, ctx, settings, seed)``: a procedure's part of ``[scene]``.
SceneReader = Callable[[Table, Context, HeadSettings, int], SceneSpec]


def targets_reader(procedure: str, *, required: bool) -> SceneReader:
    """The reader of ``[[scene.targets]]`` and ``[scene.random_targets]`` in the default
    scene, checked for ``procedure``'s reach (``required``: at least one target)."""

    def read(table: Table, ctx: Context, settings: HeadSettings, seed: int) -> SceneSpec:
        targets, acceptance = _read_targets(
            table, settings, seed, required=required, procedure=procedure
        )
        return SceneSpec(scene="default", targets=targets, acceptance=acceptance)

    return read


def read_pursuit_scene(table: Table, ctx: Context, settings: HeadSettings, seed: int) -> SceneSpec:
    """``[scene.pursuit]`` in the default scene: its ``body`` a marker or an object of
    ``[scene.room]`` (tracked markerlessly from a click)."""
    bodies = (*MARKER_BODIES, *ROOM_OBJECTS.get())
    return SceneSpec(scene="default", pursuit=read_pursuit(table, seed, bodies))


def finite_number(table: Table, key: str, value: Any) -> float:
    """``value`` at ``key``, a number within +-MAX_DEPTH_M m (else the table's error)."""
    return table._check_number(
        key, value, -MAX_DEPTH_M, MAX_DEPTH_M, False, False, f"numbers within +-{MAX_DEPTH_M:g} m"
    )
