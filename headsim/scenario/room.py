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
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from headsim.scenario.occlusion import Occluder, scene_model
from headsim.scenario.spec import MAX_DEPTH_M, TARGETS_AS, ListedSurfaceTarget, SurfaceTargetsSpec
from headsim.scenario.surface_targets import NotOnSurface, on_object, on_surface
from headsim.scenario.tables import Table
from headsim.sim import names
from headsim.sim.declared import Array, Choice, Flag, Section, Setting, Text
from headsim.sim.textured_scene import (
    SHAPES,
    LightSettings,
    RoomSpec,
    SceneObject,
    Vec3,
    add_shape,
)
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


#: A mesh object's largest vertex count and coordinate (object frame), m.
MAX_MESH_VERTICES, MAX_MESH_M = 1000, 2.0


_PI = math.pi
# fmt: off
_NAME = Text("name", None, "The object's name, unique (default `item_N`; `clutter_`, `room_` and the scenes' bodies are reserved).", max_length=60, derived=True)
_SHAPE = Choice("shape", tuple(SHAPES), None, "`box`, `cylinder`, `sphere`, `plane` or `mesh` (its `vertices_m` and `faces`, no `size_m`).", required=True)
_VERTICES = Array("vertices_m", f"4 to {MAX_MESH_VERTICES} points [x, y, z] in the object's frame, m", "`mesh`: its vertices [[x, y, z], ...] in the object's frame (4-1000, within 2 m of its origin), m.", required=True)
_FACES = Array("faces", "triangles [i, j, k] of vertex indices, counter-clockwise seen from outside, at least 4, each with an area", "`mesh`: its triangles [[i, j, k], ...] of vertex indices, counter-clockwise seen from outside (each textured by projecting it onto the object-frame plane it faces most).", required=True)
_SIZE = Setting("size_m", None, 0.0, 5.0, "m", "MuJoCo's sizes, m: a box's half-lengths, a cylinder's radius and half-height (then 0), a sphere's radius (then 0, 0), a plane's half-sides (then 0).", count=3, optional=True)
_POS = Setting("pos_world_m", None, -MAX_DEPTH_M, MAX_DEPTH_M, "m", "The object's centre in W, m.", count=3, required=True)
_YAW = Setting("yaw_rad", 0.0, -_PI, _PI, "rad", "Rotation about W's z, rad.")
_PITCH = Setting("pitch_rad", 0.0, -_PI, _PI, "rad", "Then about the object's own x, rad (a plane at pi/2 stands up facing the head).")
_TEXTURE = Choice("texture", TEXTURE_KINDS, "pink", "Texture class: `pink`, `grating`, `low` or `repetitive`.")
_TEXTURE_SEED = Setting("texture_seed", None, 0, 2**31 - 1, "", "Seed of the object's texture; default from the scenario's seed.", integer=True)
_PERIOD = Setting("period_px", 16.0, 2.0, 256.0, "px", "`grating` and `repetitive`: the period in texture pixels (256 to a tile).")
_ORIENTATION = Setting("orientation_rad", 0.0, -_PI, _PI, "rad", "`grating` and `repetitive`: direction the pattern varies along, rad from the texture's columns.")
_CHECKS = Flag("checks", False, "`repetitive`: checks instead of stripes.")
_TILE = Setting("tile_m", 0.5, 0.0, 10.0, "m", "`plane` and `mesh`: the side of one texture tile on the surface, m.", lo_open=True)
OBJECTS = Section("scene.room.objects", "Textured objects placed in the room.", (_NAME, _SHAPE, _VERTICES, _FACES, _SIZE, _POS, _YAW, _PITCH, _TEXTURE, _TEXTURE_SEED, _PERIOD, _ORIENTATION, _CHECKS, _TILE), many=100)
_LIGHT = LightSettings()
_DIRECTION = Setting("direction_world", _LIGHT.direction_world, -1.0, 1.0, "", "Direction the key light shines along, in W (normalised).", count=3)
_DIFFUSE = Setting("diffuse", _LIGHT.diffuse, 0.0, 1.0, "", "Key light's diffuse intensity, 0-1.")
_AMBIENT = Setting("ambient", _LIGHT.ambient, 0.0, 1.0, "", "Ambient light everywhere, 0-1.")
_SHADOWS = Flag("shadows", _LIGHT.shadows, "Whether the key light casts shadows (a shadow map: dearer renders).")
LIGHT = Section("scene.room.light", "The key light and the ambient level.", (_DIRECTION, _DIFFUSE, _AMBIENT, _SHADOWS))
_TARGET_NAME = Text("name", None, "The listed target's name, unique (`surface_` is reserved for drawn ones). Listed targets are measured in file order.", max_length=60, what="the target's name", required=True)
_TARGET_OBJECT = Text("object", None, "The room object the point lies on (an objects entry, `clutter_N`, `room_floor`, `room_table`, `room_wall_*`).", max_length=60, what="the name of an object of the room")
_IN_OBJECT = Setting("point_object_m", None, -MAX_DEPTH_M, MAX_DEPTH_M, "m", "The point in the object's frame, m; must lie within 1 mm of its surface.", count=3, optional=True)
_IN_WORLD = Setting("point_world_m", None, -MAX_DEPTH_M, MAX_DEPTH_M, "m", "Without `object`: the point in W, m; must lie within 1 mm of a surface of the room.", count=3, optional=True)
TARGETS = Section("scene.room.targets", "Markerless targets (`model2`, `model1`; told by a click in camera 1's image): a count drawn from the seed where the start pose shows both cameras (0: none), or a list.", (_TARGET_NAME, _TARGET_OBJECT, _IN_OBJECT, _IN_WORLD), many=200)
_COUNT = Setting("targets", 0, 0, 200, "", TARGETS.meaning, integer=True)
_TARGETS_DEPTH = Setting("targets_depth_m", (0.3, 2.0), 0.2, MAX_DEPTH_M, "m", "Depth range in H of the markerless targets, m (a draw outside is drawn again, counted).", count=2)
_TARGETS_LATERAL = Setting("targets_lateral", 0.25, 0.0, 1.0, "", "Largest |x_h / z_h| of a markerless target's draw direction (0.25: the shared field).", lo_open=True)
_TARGETS_VERTICAL = Setting("targets_vertical", 0.1, 0.0, 1.0, "", "Largest |y_h / z_h| of a markerless target's draw direction.", lo_open=True)
_CLICK = Setting("click_error_px", 0.5, 0.0, 20.0, "px", "Standard deviation of the click that tells the head a markerless target, px per axis.")
_BAND = Setting("band_px", 10.0, 1.0, 100.0, "px", "Half-height of the band along camera 1's row in which camera 2 searches the clicked point, px (the head knows no focal length).")
_TARGETS_AS = Choice("targets_as", TARGETS_AS, "surface", "`surface`: each target by correlation; `markers`: an emissive marker put 5 mm out along the surface's normal, found by its colour (the marker twin).")
_SURFACE = Choice("surface", TEXTURE_KINDS, "pink", "Texture class of the floor, walls and table: `pink` (1/f noise), `grating`, `low` (faint gradient), `repetitive` (stripes).")
_TABLE_Z = Setting("table_top_z_m", RoomSpec.table_top_z_m, RoomSpec.floor_z_m, RoomSpec.wall_top_z_m, "m", "Height of the table top in W's z, m (the eyes are about 0.2 m up; default -0.35); the clutter rests on it.", lo_open=True, hi_open=True)
_CLUTTER = Setting("clutter", 8, 0, 40, "", "Objects drawn from the seed (box, cylinder or sphere, 3-8 cm half-size, a texture class each), resting on the table.", integer=True)
_CLUTTER_DEPTH = Setting("clutter_depth_m", (0.3, 2.0), 0.2, 2.1, "m", "Range of W's y (depth in front of the head) of the clutter's centres, m.", count=2)
ROOM = Section("scene.room", "A textured room around the head (every procedure): floor, walls and table with generated textures, objects, clutter from the seed, and the light.", (_COUNT, _TARGETS_DEPTH, _TARGETS_LATERAL, _TARGETS_VERTICAL, _CLICK, _BAND, _TARGETS_AS, _SURFACE, _TABLE_Z, _CLUTTER, _CLUTTER_DEPTH))
#: ``[scene.room]`` and its tables, as the key reference lists them.
SECTIONS = (ROOM, LIGHT, OBJECTS, TARGETS)
# fmt: on


def _mesh(table: Table) -> tuple[tuple[Vec3, ...], tuple[tuple[int, int, int], ...]]:
    """A ``mesh`` object's ``vertices_m`` and ``faces``, checked: every index a vertex, no
    face without area."""
    vertices = table.points(_VERTICES, 4, MAX_MESH_VERTICES, MAX_MESH_M)
    count = len(vertices)
    allowed = (
        f"triangles [i, j, k] of vertex indices 0-{count - 1}, counter-clockwise seen from "
        "outside, at least 4, each with an area"
    )
    raw = table.data.get(_FACES.name)
    table.has(_FACES.name)
    if not isinstance(raw, list) or not 4 <= len(raw) <= 4 * MAX_MESH_VERTICES:
        raise table.fail("faces", "missing" if raw is None else "wrong length or type", allowed)
    faces = []
    points = np.asarray(vertices)
    for i, f in enumerate(raw):
        ok = isinstance(f, list) and len(f) == 3
        ok = ok and all(isinstance(j, int) and not isinstance(j, bool) for j in f)
        if not ok or not all(0 <= j < count for j in f):
            raise table.fail(f"faces[{i}]", "must be three vertex indices", allowed)
        a, b, c = points[f[0]], points[f[1]], points[f[2]]
        if float(np.linalg.norm(np.cross(b - a, c - a))) < 1e-10:
            raise table.fail(f"faces[{i}]", "has no area", allowed)
        faces.append((f[0], f[1], f[2]))
    return tuple(vertices), tuple(faces)


def _object(table: Table, k: int, seed: int) -> SceneObject:
    """One ``[[scene.room.objects]]`` entry."""
    name = table.setting(_NAME, f"item_{k + 1}")
    shape = table.setting(_SHAPE)
    if shape == "mesh":
        vertices, faces = _mesh(table)
        size: tuple[float, ...] | None = (0.0, 0.0, 0.0)
    else:
        vertices, faces = (), ()
        size = table.setting(_SIZE)
    if size is None or (
        shape != "mesh" and min(size[: {"sphere": 1, "cylinder": 2}.get(shape, 2)]) <= 0.0
    ):
        raise table.fail(
            "size_m",
            "missing or not positive" if size is None else "a size that is not positive",
            "[a, b, c] m > 0: a box's half-lengths, a cylinder's radius and half-height, a "
            "sphere's radius (then 0, 0), a plane's half-sides (then 0)",
        )
    pos, yaw, pitch = table.setting(_POS), table.setting(_YAW), table.setting(_PITCH)
    texture = TextureSpec(
        table.setting(_TEXTURE),
        seed=table.setting(_TEXTURE_SEED, seed * 100 + k),
        period_px=table.setting(_PERIOD),
        orientation_rad=table.setting(_ORIENTATION),
        checks=table.setting(_CHECKS),
    )
    tile = table.setting(_TILE)
    table.done()
    full = (size[0], size[1], 1.0 if shape == "plane" else size[2])
    return SceneObject(
        name, shape, full, (pos[0], pos[1], pos[2]), texture, yaw, pitch, tile,
        vertices_m=vertices, faces=faces,
    )  # fmt: skip


@functools.cache
def scene_names() -> frozenset[str]:
    """Every body and geom name of the shipped scenes (an object may not take one)."""
    taken: set[str] = set()
    for scene in names.SCENES:
        model = scene_model(scene)
        taken.update(model.body(b).name for b in range(model.nbody))
        taken.update(model.geom(g).name for g in range(model.ngeom))
    return frozenset(taken)


def _listed(entry: Table) -> ListedSurfaceTarget:
    """One ``[[scene.room.targets]]`` entry (its point checked later, with the room)."""
    name, body, in_object, in_world = (
        entry.setting(d) for d in (_TARGET_NAME, _TARGET_OBJECT, _IN_OBJECT, _IN_WORLD)
    )
    entry.done()
    if body is not None and (in_object is None or in_world is not None):
        raise entry.fail(
            "point_object_m",
            "missing" if in_object is None else "given with point_world_m",
            "with object: point_object_m = [x, y, z] in the object's frame, m (no point_world_m)",
        )
    if body is None and (in_world is None or in_object is not None):
        raise entry.fail(
            "point_world_m",
            "missing" if in_world is None else "given with point_object_m but no object",
            "point_world_m = [x, y, z] on a surface, m; or object and point_object_m",
        )
    point = in_object if body is not None else in_world
    assert point is not None
    return ListedSurfaceTarget(name, body, (point[0], point[1], point[2]))


def _surface_targets(table: Table) -> SurfaceTargetsSpec | None:
    """``[scene.room]``'s markerless targets (``targets``: a count drawn from the seed, or
    ``[[scene.room.targets]]`` listed; its ``targets_*`` keys, ``click_error_px``,
    ``band_px``); None when there are none."""
    listed: tuple[ListedSurfaceTarget, ...] = ()
    if isinstance(table.data.get(_COUNT.name), list):
        # TOML gives a key one type: listed targets leave no count to draw.
        listed = tuple(_listed(t) for t in table.sections(TARGETS))
        count = 0
    else:
        count = table.setting(_COUNT)
    near, far = table.setting(_TARGETS_DEPTH)
    if near >= far:
        raise table.fail(
            "targets_depth_m", f"[{near:g}, {far:g}] is empty", "[near, far], near < far"
        )
    lateral, vertical = table.setting(_TARGETS_LATERAL), table.setting(_TARGETS_VERTICAL)
    click_px, band_px = table.setting(_CLICK), table.setting(_BAND)
    targets_as = table.setting(_TARGETS_AS)
    if count == 0 and not listed:
        return None
    return SurfaceTargetsSpec(
        count, (near, far), lateral, vertical, click_px, band_px, listed, targets_as
    )


@dataclass(frozen=True)
class RoomGeometry:
    """The room's surfaces and objects alone, compiled, at rest (no head, no textures): for
    checking that a listed target lies on a surface when the scenario is read."""

    model: mujoco.MjModel
    data: mujoco.MjData

    @classmethod
    def of(cls, room: RoomSpec) -> RoomGeometry:
        spec = mujoco.MjSpec()
        for obj in (*room.surfaces(), *room.objects):
            add_shape(spec, replace(obj, movable=False))
        model = spec.compile()
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
        return cls(model, data)


def check_listed(scene: Table, room: RoomSpec, listed: tuple[ListedSurfaceTarget, ...]) -> None:
    """Each listed target's name unique and its point on its object's surface (or, a world
    point, on some surface), else a one-line error naming the entry's field."""
    if not listed:
        return
    geometry = RoomGeometry.of(room)
    bodies = [obj.name for obj in (*room.surfaces(), *room.objects)]
    path = f"{scene.field('room')}.targets"
    seen: list[str] = []
    for k, t in enumerate(listed):
        if t.name in seen or t.name.startswith("surface_"):
            raise scene.ctx.error(
                f"{path}[{k}].name",
                f"{t.name!r} is used twice or reserved",
                "unique names, not starting with surface_ (the drawn targets' names)",
            )
        seen.append(t.name)
        if t.body is not None and t.body not in bodies:
            raise scene.ctx.error(
                f"{path}[{k}].object",
                f"no object named {t.body!r} in the room",
                "an object of [[scene.room.objects]], clutter_N, room_floor, room_table, "
                + ", ".join(names.ROOM_WALLS),
            )
        try:
            if t.body is not None:
                on_object(geometry, t.name, t.body, t.point_m)
            else:
                on_surface(geometry, t.name, t.point_m)
        except NotOnSurface as error:
            key = "point_object_m" if t.body is not None else "point_world_m"
            # The message says what is allowed (within ON_SURFACE_M).
            raise scene.ctx.error(f"{path}[{k}].{key}", str(error)) from None


def read_room(scene: Table, seed: int) -> tuple[RoomSpec | None, SurfaceTargetsSpec | None]:
    """``[scene.room]``, its ``light`` and ``objects``, and its markerless targets;
    (None, None) without it."""
    table = scene.section(ROOM)
    if table is None:
        return None, None
    targets = _surface_targets(table)
    surface, table_z = table.setting(_SURFACE), table.setting(_TABLE_Z)
    count = table.setting(_CLUTTER)
    near, far = table.setting(_CLUTTER_DEPTH)
    if near >= far:
        raise table.fail(
            "clutter_depth_m", f"[{near:g}, {far:g}] is empty", "[near, far], near < far"
        )
    light_table = table.section(LIGHT)
    light = LightSettings()
    if light_table is not None:
        direction = light_table.setting(_DIRECTION)
        if not any(direction):
            raise light_table.fail("direction_world", "is zero", "a direction [x, y, z] != 0")
        light = LightSettings(
            direction_world=(direction[0], direction[1], direction[2]),
            diffuse=light_table.setting(_DIFFUSE),
            ambient=light_table.setting(_AMBIENT),
            shadows=light_table.setting(_SHADOWS),
        )
        light_table.done()
    objects = tuple(_object(t, k, seed) for k, t in enumerate(table.sections(OBJECTS)))
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
    room = replace(room, objects=objects + clutter)
    if targets is not None:
        check_listed(scene, room, targets.listed)
    return room, targets


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
            "mesh": max((float(np.linalg.norm(v)) for v in obj.vertices_m), default=0.0),
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
    "RoomGeometry",
    "check_listed",
    "draw_clutter",
    "read_room",
    "room_occluders",
]
