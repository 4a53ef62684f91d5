"""A room made from a seed: textured floor, walls and table, textured objects on it, and
the light as settings, added to a scene's spec (:func:`add_room`).

Textures are generated (:mod:`headsim.sim.textures`) and handed to MuJoCo as texture
data through MjSpec: nothing is read from disk or fetched.  Planes (floor, walls) take
a 2-D texture repeated so that one tile spans ``tile_m`` metres (``texuniform`` off,
``texrepeat`` = plane side / tile); rendered from above, texture column j runs along
the plane's +x and row 0 lies at its +y edge (checked by rendering,
tests/sim/test_textured_scene.py).  Boxes, cylinders and spheres take a cube texture,
the one image on each face.  The head's own model is left as it is: the room replaces
only the scene's table plane and key light, and sets the headlight's ambient level.
Positions in W, m; ``size_m`` as MuJoCo's geom sizes (half-lengths, radii).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from headsim.sim import names
from headsim.sim.textures import TEXTURE_KINDS, TextureSpec, texture_grey, tint_of, to_rgb

#: The shapes an object may have, and MuJoCo's geom type for each.
SHAPES = {
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "plane": mujoco.mjtGeom.mjGEOM_PLANE,
    "mesh": mujoco.mjtGeom.mjGEOM_MESH,
}

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class LightSettings:
    """The key light: ``direction_world`` it shines along (normalised when built),
    ``diffuse`` intensity 0..1, the ``ambient`` level 0..1 everywhere, ``shadows`` on or off
    (a shadow map: dearer renders)."""

    direction_world: Vec3 = (0.3, 0.5, -1.0)
    diffuse: float = 0.6
    ambient: float = 0.3
    shadows: bool = False


@dataclass(frozen=True)
class SceneObject:
    """A textured object: ``shape`` (:data:`SHAPES`), ``size_m`` (MuJoCo's geom sizes: a box's
    half-lengths, a cylinder's radius and half-height, a sphere's radius, a plane's
    half-sides), its centre ``pos_world_m``, ``yaw_rad`` about W's z, and an extra
    ``pitch_rad`` about its own x (a plane stood up: pi/2 faces -y, toward the head);
    ``texture`` and ``tile_m``, the side of one texture tile on a plane or a mesh, m;
    ``movable``: on a mocap body (the live head moves it along a path), else a static one.
    A ``mesh``: ``vertices_m`` in the object's frame and triangular ``faces`` (vertex
    indices, counter-clockwise seen from outside); each face is textured by projecting
    it onto the object-frame plane it faces most, one tile per ``tile_m``."""

    name: str
    shape: str
    size_m: Vec3
    pos_world_m: Vec3
    texture: TextureSpec
    yaw_rad: float = 0.0
    pitch_rad: float = 0.0
    tile_m: float = 0.5
    movable: bool = False
    vertices_m: tuple[Vec3, ...] = ()
    faces: tuple[tuple[int, int, int], ...] = ()

    @property
    def world_from_object(self) -> np.ndarray:
        """The object's rotation in W, 3 x 3: yaw about z, then pitch about its x."""
        cy, sy = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        cp, sp = math.cos(self.pitch_rad), math.sin(self.pitch_rad)
        yaw = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
        pitch = np.array([[1.0, 0.0, 0.0], [0.0, cp, -sp], [0.0, sp, cp]])
        return yaw @ pitch


@dataclass(frozen=True)
class RoomSpec:
    """A room around the head: a floor at ``floor_z_m`` (W's z), walls up to
    ``wall_top_z_m``, a back wall at ``back_wall_y_m``, side walls at +-``side_wall_x_m``
    (open behind the head, where the floor and side walls end 1 m back), a table whose top is at
    ``table_top_z_m`` spanning ``table_x_m`` and ``table_y_m`` (each a (min, max)), each
    with a texture of ``surface`` kind from the seed; ``objects`` on it; ``light``.
    ``plain``: no floor, walls or table, only the objects before MuJoCo's plain background
    (a scene that fills the view with its objects renders fastest so)."""

    seed: int = 0
    surface: str = "pink"
    floor_z_m: float = -1.1
    back_wall_y_m: float = 3.0
    side_wall_x_m: float = 2.0
    wall_top_z_m: float = 2.0
    table_top_z_m: float = -0.35
    table_x_m: tuple[float, float] = (-0.9, 0.9)
    table_y_m: tuple[float, float] = (0.15, 2.1)
    objects: tuple[SceneObject, ...] = ()
    light: LightSettings = field(default_factory=LightSettings)
    plain: bool = False

    def surfaces(self) -> tuple[SceneObject, ...]:
        """The floor, the walls and the table, as textured objects; each plane faces into
        the room (MuJoCo draws a plane, and ``mj_ray`` meets it, from the front).  No
        ceiling: it would shadow the whole room from the key light.  None when ``plain``."""
        if self.plain:
            return ()
        x0, x1 = self.table_x_m
        y0, y1 = self.table_y_m
        half_height = (self.wall_top_z_m - self.floor_z_m) / 2
        mid_z = (self.wall_top_z_m + self.floor_z_m) / 2
        depth = self.back_wall_y_m - (-1.0)
        mid_y = (self.back_wall_y_m - 1.0) / 2

        def tex(k: int) -> TextureSpec:
            return TextureSpec(self.surface, seed=self.seed * 1000 + k, contrast=0.6)

        p = math.pi / 2
        thick = 0.02
        return (
            SceneObject(
                names.ROOM_FLOOR, "plane", (self.side_wall_x_m, depth / 2, 1.0),
                (0.0, mid_y, self.floor_z_m), tex(1), tile_m=1.0,
            ),
            SceneObject(
                names.ROOM_WALLS[0], "plane", (self.side_wall_x_m, half_height, 1.0),
                (0.0, self.back_wall_y_m, mid_z), tex(2), pitch_rad=p, tile_m=1.0,
            ),
            SceneObject(
                names.ROOM_WALLS[1], "plane", (depth / 2, half_height, 1.0),
                (-self.side_wall_x_m, mid_y, mid_z), tex(3), yaw_rad=p, pitch_rad=p, tile_m=1.0,
            ),
            SceneObject(
                names.ROOM_WALLS[2], "plane", (depth / 2, half_height, 1.0),
                (self.side_wall_x_m, mid_y, mid_z), tex(4), yaw_rad=-p, pitch_rad=p, tile_m=1.0,
            ),
            SceneObject(
                names.ROOM_TABLE, "box", ((x1 - x0) / 2, (y1 - y0) / 2, thick),
                ((x0 + x1) / 2, (y0 + y1) / 2, self.table_top_z_m - thick), tex(5),
            ),
        )  # fmt: skip


@functools.lru_cache(maxsize=128)
def texture_bytes(texture: TextureSpec) -> bytes:
    """``texture``'s tinted 8-bit RGB pixels, row by row (made once per spec: every
    simulator of a run builds the same room)."""
    return to_rgb(texture_grey(texture), tint_of(texture.seed)).tobytes()


def mesh_texcoords(
    vertices_m: np.ndarray, faces: np.ndarray, tile_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Per face corner texture coordinates of a mesh, (3 F, 2), and their indices per face,
    (F, 3): each face projected onto the object-frame plane its normal is nearest (x-y,
    y-z or z-x), one texture tile per ``tile_m`` metres."""
    corners = np.asarray(vertices_m, dtype=float)[np.asarray(faces, dtype=int)]  # F x 3 x 3
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    axis = np.argmax(np.abs(normals), axis=1)
    # The two other axes, in the order that keeps each projection right-handed.
    across = np.array([[1, 2], [2, 0], [0, 1]])[axis]
    u = np.take_along_axis(corners, across[:, None, 0:1].repeat(3, axis=1), axis=2)[..., 0]
    v = np.take_along_axis(corners, across[:, None, 1:2].repeat(3, axis=1), axis=2)[..., 0]
    uv = np.stack([u, v], axis=-1).reshape(-1, 2) / tile_m
    return uv, np.arange(uv.shape[0]).reshape(-1, 3)


def _texture(spec: mujoco.MjSpec, name: str, obj: SceneObject) -> str:
    """Add ``obj``'s texture and material to ``spec``; the material's name."""
    n = obj.texture.size_px
    plane = obj.shape == "plane"
    flat = plane or obj.shape == "mesh"  # its own texture coordinates: a 2-D texture
    kind = mujoco.mjtTexture.mjTEXTURE_2D if flat else mujoco.mjtTexture.mjTEXTURE_CUBE
    texture = spec.add_texture(name=f"{name}_texture", type=kind, width=n, height=n, nchannel=3)
    texture.data = texture_bytes(obj.texture)
    material = spec.add_material(name=f"{name}_material")
    material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = texture.name
    material.specular = 0.0
    material.shininess = 0.0
    material.texuniform = False
    if plane:
        material.texrepeat = [
            2 * obj.size_m[0] / obj.tile_m,
            2 * obj.size_m[1] / obj.tile_m,
        ]
    return str(material.name)


def add_object(spec: mujoco.MjSpec, obj: SceneObject) -> None:
    """Add ``obj`` to ``spec`` on a body of its name (geom and body named alike; a mocap
    body when ``obj.movable``), with its texture."""
    if obj.texture.kind not in TEXTURE_KINDS:
        raise ValueError(f"unknown texture {obj.texture.kind!r}")
    add_shape(spec, obj, _texture(spec, obj.name, obj))


def add_shape(spec: mujoco.MjSpec, obj: SceneObject, material: str = "") -> None:
    """Add ``obj``'s body and geom (and a mesh's mesh) to ``spec``, with ``material`` (""
    none: the geometry alone, as the reach check's occlusion model takes it)."""
    if obj.shape not in SHAPES:
        raise ValueError(f"unknown shape {obj.shape!r}; allowed: {', '.join(SHAPES)}")
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(obj.world_from_object).reshape(9))
    body = spec.worldbody.add_body(
        name=obj.name, pos=list(obj.pos_world_m), quat=list(quat), mocap=obj.movable
    )
    mesh = ""
    if obj.shape == "mesh":
        vertices = np.asarray(obj.vertices_m, dtype=float)
        faces = np.asarray(obj.faces, dtype=int)
        uv, uv_faces = mesh_texcoords(vertices, faces, obj.tile_m)
        added = spec.add_mesh(name=f"{obj.name}_mesh")
        added.uservert = vertices.reshape(-1).tolist()
        added.userface = faces.reshape(-1).tolist()
        added.usertexcoord = uv.reshape(-1).tolist()
        added.userfacetexcoord = uv_faces.reshape(-1).tolist()
        added.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL  # open meshes too
        mesh = f"{obj.name}_mesh"
    body.add_geom(
        name=obj.name,
        type=SHAPES[obj.shape],
        size=list(obj.size_m),
        meshname=mesh,
        material=material,
        contype=0,
        conaffinity=0,
        group=names.ROOM_GROUP,
    )


def add_room(spec: mujoco.MjSpec, room: RoomSpec) -> None:
    """Put ``room`` into ``spec``, a scene with the head: its surfaces and objects in place
    of the table plane, its light in place of the key light."""
    for geom in spec.geoms:
        if geom.name == names.TABLE_PLANE:
            spec.delete(geom)
            break
    for obj in (*room.surfaces(), *room.objects):
        add_object(spec, obj)
    light = room.light
    direction = np.asarray(light.direction_world, dtype=float)
    direction /= np.linalg.norm(direction)
    key = next((lt for lt in spec.lights if lt.name == names.KEY_LIGHT), None)
    if key is None:
        key = spec.worldbody.add_light(name=names.KEY_LIGHT)
    key.type = mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    key.pos = list(-3.0 * direction)
    key.dir = list(direction)
    key.diffuse = [light.diffuse] * 3
    key.specular = [0.0] * 3
    key.ambient = [0.0] * 3
    key.castshadow = light.shadows
    headlight = spec.visual.headlight
    headlight.active = 1
    headlight.ambient = [light.ambient] * 3
    headlight.diffuse = [0.0] * 3
    headlight.specular = [0.0] * 3
    if light.shadows:
        spec.visual.quality.shadowsize = 2048
        # The shadow map covers the lit region: the room, not the default 50 m extent.
        spec.stat.extent = 4.0


__all__ = [
    "SHAPES",
    "LightSettings",
    "RoomSpec",
    "SceneObject",
    "add_object",
    "add_room",
    "add_shape",
    "mesh_texcoords",
]
