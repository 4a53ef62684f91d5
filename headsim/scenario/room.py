"""``[scene.room]``: a textured room around the head, its objects and its light
(:mod:`headsim.sim.textured_scene`), read from the scenario and drawn from its seed;
and what of it can hide a target (for the reach check's occlusion test).

Clutter is drawn from the scenario's seed (stream :data:`STREAM_ROOM`): each piece a
box, cylinder or sphere 3-8 cm in half-size, resting on the table at a depth in
``clutter_depth_m``, with a texture class and seed of its own.
"""

from __future__ import annotations

import functools
import math
from contextvars import ContextVar
from dataclasses import replace

import numpy as np

from headsim.scenario.occlusion import Occluder, scene_model
from headsim.scenario.spec import MAX_DEPTH_M, SurfaceTargetsSpec
from headsim.scenario.tables import Table
from headsim.sim import names
from headsim.sim.textured_scene import SHAPES, LightSettings, RoomSpec, SceneObject
from headsim.sim.textures import TEXTURE_KINDS, TextureSpec

#: The seed's stream for the room's clutter and textures (after ``spec.STREAM_*``).
STREAM_ROOM = 6

#: Thinnest half-size, m, below which a box counts as a plane for occlusion (a table top).
THIN_M = 0.03

#: Whether the room has markerless targets, while the scene's marker targets are read
#: (then a procedure that requires targets needs no marker ones).
ROOM_HAS_TARGETS: ContextVar[bool] = ContextVar("room_has_targets", default=False)

#: What can hide a target besides the scene's own geoms, while a room's targets are read.
ROOM_OCCLUDERS: ContextVar[tuple[Occluder, ...]] = ContextVar("room_occluders", default=())


def draw_clutter(
    room: RoomSpec, count: int, depth_m: tuple[float, float], rng: np.random.Generator
) -> tuple[SceneObject, ...]:
    """``count`` objects resting on ``room``'s table, centres at W's y in ``depth_m``."""
    x0, x1 = room.table_x_m
    y0, y1 = max(room.table_y_m[0], depth_m[0]), min(room.table_y_m[1], depth_m[1])
    out = []
    for k in range(count):
        shape = str(rng.choice(("box", "cylinder", "sphere")))
        a, b, c = (float(v) for v in rng.uniform(0.03, 0.08, 3))
        size = {"box": (a, b, c), "cylinder": (a, c, 0.0), "sphere": (a, 0.0, 0.0)}[shape]
        half_height = {"box": c, "cylinder": c, "sphere": a}[shape]
        texture = TextureSpec(
            str(rng.choice(TEXTURE_KINDS)),
            seed=int(rng.integers(0, 2**31)),
            period_px=float(rng.uniform(8.0, 32.0)),
            orientation_rad=float(rng.uniform(0.0, math.pi)),
            checks=bool(rng.integers(0, 2)),
        )
        pos = (
            float(rng.uniform(x0 + 0.1, x1 - 0.1)),
            float(rng.uniform(y0, y1)),
            room.table_top_z_m + half_height,
        )
        yaw = float(rng.uniform(0.0, math.pi))
        out.append(SceneObject(f"clutter_{k + 1}", shape, size, pos, texture, yaw_rad=yaw))
    return tuple(out)


def _object(table: Table, k: int, seed: int) -> SceneObject:
    """One ``[[scene.room.objects]]`` entry."""
    name = table.string("name", f"item_{k + 1}", 60)
    shape = table.choice("shape", tuple(SHAPES))
    size = table.numbers("size_m", 3, None, 0.0, 5.0, unit="m")
    if size is None or min(size[: {"sphere": 1, "cylinder": 2}.get(shape, 2)]) <= 0.0:
        raise table.fail(
            "size_m",
            "missing or not positive" if size is None else "a size that is not positive",
            "[a, b, c] m > 0: a box's half-lengths, a cylinder's radius and half-height, a "
            "sphere's radius (then 0, 0), a plane's half-sides (then 0)",
        )
    pos = table.numbers("pos_world_m", 3, lo=-MAX_DEPTH_M, hi=MAX_DEPTH_M, unit="m")
    yaw = table.number("yaw_rad", 0.0, -math.pi, math.pi, unit="rad")
    pitch = table.number("pitch_rad", 0.0, -math.pi, math.pi, unit="rad")
    texture = TextureSpec(
        table.choice("texture", TEXTURE_KINDS, "pink"),
        seed=table.integer("texture_seed", seed * 100 + k, 0, 2**31 - 1),
        period_px=table.number("period_px", 16.0, 2.0, 256.0, unit="px"),
        orientation_rad=table.number("orientation_rad", 0.0, -math.pi, math.pi, unit="rad"),
        checks=table.boolean("checks", False),
    )
    tile = table.number("tile_m", 0.5, 0.0, 10.0, lo_open=True, unit="m")
    table.done()
    full = (size[0], size[1], 1.0 if shape == "plane" else size[2])
    return SceneObject(name, shape, full, (pos[0], pos[1], pos[2]), texture, yaw, pitch, tile)


@functools.cache
def scene_names() -> frozenset[str]:
    """Every body and geom name of the shipped scenes (an object may not take one)."""
    taken: set[str] = set()
    for scene in names.SCENES:
        model = scene_model(scene)
        taken.update(model.body(b).name for b in range(model.nbody))
        taken.update(model.geom(g).name for g in range(model.ngeom))
    return frozenset(taken)


def _surface_targets(table: Table) -> SurfaceTargetsSpec | None:
    """``[scene.room]``'s markerless targets (``targets`` and its ``targets_*`` keys,
    ``click_error_px``, ``band_px``); None when ``targets`` is 0 or absent."""
    count = table.integer("targets", 0, 0, 200)
    near, far = table.numbers("targets_depth_m", 2, (0.3, 2.0), 0.2, MAX_DEPTH_M, unit="m")
    if near >= far:
        raise table.fail(
            "targets_depth_m", f"[{near:g}, {far:g}] is empty", "[near, far], near < far"
        )
    lateral = table.number("targets_lateral", 0.25, 0.0, 1.0, lo_open=True)
    vertical = table.number("targets_vertical", 0.1, 0.0, 1.0, lo_open=True)
    click_px = table.number("click_error_px", 0.5, 0.0, 20.0, unit="px")
    band_px = table.number("band_px", 10.0, 1.0, 100.0, unit="px")
    if count == 0:
        return None
    return SurfaceTargetsSpec(count, (near, far), lateral, vertical, click_px, band_px)


def read_room(scene: Table, seed: int) -> tuple[RoomSpec | None, SurfaceTargetsSpec | None]:
    """``[scene.room]``, its ``light`` and ``objects``, and its markerless targets;
    (None, None) without it."""
    table = scene.table("room")
    if table is None:
        return None, None
    targets = _surface_targets(table)
    surface = table.choice("surface", TEXTURE_KINDS, "pink")
    floor, top = RoomSpec.floor_z_m, RoomSpec.wall_top_z_m
    table_z = table.number(
        "table_top_z_m", RoomSpec.table_top_z_m, floor, top, lo_open=True, hi_open=True, unit="m"
    )
    count = table.integer("clutter", 8, 0, 40)
    near, far = table.numbers("clutter_depth_m", 2, (0.3, 2.0), 0.2, 2.1, unit="m")
    if near >= far:
        raise table.fail(
            "clutter_depth_m", f"[{near:g}, {far:g}] is empty", "[near, far], near < far"
        )
    light_table = table.table("light")
    light = LightSettings()
    if light_table is not None:
        direction = light_table.numbers("direction_world", 3, light.direction_world, -1.0, 1.0)
        if not any(direction):
            raise light_table.fail("direction_world", "is zero", "a direction [x, y, z] != 0")
        light = LightSettings(
            direction_world=(direction[0], direction[1], direction[2]),
            diffuse=light_table.number("diffuse", light.diffuse, 0.0, 1.0),
            ambient=light_table.number("ambient", light.ambient, 0.0, 1.0),
            shadows=light_table.boolean("shadows", light.shadows),
        )
        light_table.done()
    objects = tuple(_object(t, k, seed) for k, t in enumerate(table.tables("objects", 100)))
    table.done()
    given = [o.name for o in objects]
    taken = scene_names()
    for k, name in enumerate(given):
        if given.count(name) > 1 or name.startswith(("clutter_", "room_")) or name in taken:
            raise scene.ctx.error(
                f"{table.path}.objects[{k}].name",
                f"{name!r} is used twice, reserved or a name of the scene",
                "unique names, not starting with clutter_ or room_, not a body of the scenes "
                "(markers, chessboard, object_1..6)",
            )
    room = RoomSpec(seed=seed, surface=surface, light=light, table_top_z_m=table_z)
    rng = np.random.default_rng([seed, STREAM_ROOM])
    clutter = draw_clutter(room, count, (near, far), rng)
    return replace(room, objects=objects + clutter), targets


def room_occluders(room: RoomSpec) -> tuple[Occluder, ...]:
    """What of ``room`` can hide a target: planes (and thin boxes, by their mid-plane)
    as planes, the other objects by their bounding spheres."""
    out = []
    for obj in (*room.surfaces(), *room.objects):
        rotation = obj.world_from_object
        centre = np.asarray(obj.pos_world_m, dtype=float)
        size = np.asarray(obj.size_m, dtype=float)
        thin = obj.shape == "box" and float(size.min()) < THIN_M
        if obj.shape == "plane" or thin:
            axis = int(np.argmin(size)) if thin else 2
            others = [i for i in range(3) if i != axis]
            out.append(
                Occluder(
                    obj.name, obj.name, True, centre, 0.0, rotation[:, axis].copy(),
                    rotation[:, others].copy(), (float(size[others[0]]), float(size[others[1]])),
                )
            )  # fmt: skip
            continue
        radius = {
            "box": float(np.linalg.norm(size)),
            "cylinder": math.hypot(size[0], size[1]),
            "sphere": float(size[0]),
        }[obj.shape]
        out.append(
            Occluder(obj.name, obj.name, False, centre, radius, rotation[:, 2].copy(),
                     rotation[:, :2].copy(), (0.0, 0.0))
        )  # fmt: skip
    return tuple(out)


__all__ = [
    "ROOM_HAS_TARGETS",
    "ROOM_OCCLUDERS",
    "STREAM_ROOM",
    "draw_clutter",
    "read_room",
    "room_occluders",
]
