"""A MuJoCo model's visible geoms and body poses, logged to Rerun (which has no MJCF loader).

Every visible geom (alpha > 0, the head's group-3 geoms included) is logged
once under its body's entity path ``ROOT/<body>``, in the body's frame:

=========  ============================================================
MuJoCo      Rerun
=========  ============================================================
plane       ``Boxes3D`` 1 mm thick (size 0: 2 m x 2 m), ``ROOT/<body>/boxes``
box         ``Boxes3D``, ``ROOT/<body>/boxes``
sphere      ``Ellipsoids3D`` (three equal half sizes), ``.../ellipsoids``
ellipsoid   ``Ellipsoids3D``, ``.../ellipsoids``
cylinder    ``Cylinders3D``, ``.../cylinders``
capsule     ``Capsules3D`` (shifted: Rerun's starts at its end), ``.../capsules``
mesh        ``Mesh3D`` of the compiled vertices and faces, ``ROOT/<body>/<geom>``
hfield      ``Mesh3D`` of the height grid, ``ROOT/<body>/<geom>``
=========  ============================================================

Primitives of one body and kind are instances of one archetype (each
entity costs about 1.3 kB in a file, each column 0.7 kB), placed by their
centres and rotations; a mesh has its own entity with a Transform3D
body_from_geom.  SDF geoms (plugins) have no shape to draw and are reported as skipped.
Colours follow MuJoCo's rule: the geom's ``rgba`` unless it is the default
and the geom has a material, then the material's ``rgba`` times the mean
colour of its texture.  Body poses are ``Transform3D`` world_from_body at
``ROOT/<body>`` (a flat list under ``ROOT``, one entity per body), logged
by :class:`BodyPoses` whenever a body moved since it was last logged.
With ``textured=True`` a textured plane, box, cylinder or sphere (a room's) is a
Mesh3D that carries its texture instead (:mod:`headsim.runs.mjcf_textures`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import rerun as rr

from headsim.runs.mjcf_textures import TEXTURED_KINDS, textured_mesh

#: Entity path under which the model's bodies are logged.
ROOT = "/world/model"
#: MuJoCo's default geom rgba: with a material, the material's colour wins.
_DEFAULT_RGBA = np.array([0.5, 0.5, 0.5, 1.0])
#: Half thickness of a drawn plane, m, and the half size of an infinite one.
_PLANE_HALF_THICKNESS_M = 0.0005
_INFINITE_PLANE_HALF_M = 1.0


@dataclass(frozen=True)
class LoggedGeom:
    """One geom as logged: its entity path, MuJoCo type name and Rerun archetype."""

    path: str
    geom: str
    body: str
    type: str
    archetype: str


@dataclass(frozen=True)
class ModelGeometry:
    """What :func:`log_model_geometry` logged and what it left out (with why)."""

    logged: tuple[LoggedGeom, ...]
    invisible: tuple[str, ...]
    skipped: tuple[tuple[str, str], ...]


def body_name(model: mujoco.MjModel, body_id: int) -> str:
    """The body's name, ``body_<id>`` when it has none (``world`` for body 0)."""
    name = model.body(body_id).name
    return name or ("world" if body_id == 0 else f"body_{body_id}")


def geom_name(model: mujoco.MjModel, geom_id: int) -> str:
    """The geom's name, ``geom_<id>`` when it has none."""
    return model.geom(geom_id).name or f"geom_{geom_id}"


def body_path(model: mujoco.MjModel, body_id: int, root: str = ROOT) -> str:
    """Entity path of a body: ``ROOT/<body>``."""
    return f"{root}/{rr.escape_entity_path_part(body_name(model, body_id))}"


def geom_rgba(model: mujoco.MjModel, geom_id: int) -> np.ndarray:
    """The geom's colour as MuJoCo draws it (rgba in [0, 1]), texture as its mean colour."""
    rgba = np.array(model.geom_rgba[geom_id], dtype=float)
    material = int(model.geom_matid[geom_id])
    if material < 0 or not np.allclose(rgba, _DEFAULT_RGBA):
        return rgba
    rgba = np.array(model.mat_rgba[material], dtype=float)
    texture = _material_texture(model, material)
    if texture >= 0:
        rgba[:3] *= _texture_mean_rgb(model, texture)
    return rgba


def _material_texture(model: mujoco.MjModel, material: int) -> int:
    """The first texture the material uses, -1 if none."""
    ids = np.asarray(model.mat_texid[material]).ravel()
    used = ids[ids >= 0]
    return int(used[0]) if used.size else -1


def _texture_mean_rgb(model: mujoco.MjModel, texture: int) -> np.ndarray:
    """Mean colour (rgb in [0, 1]) of a texture's pixels."""
    start = int(model.tex_adr[texture])
    channels = int(model.tex_nchannel[texture])
    count = int(model.tex_width[texture]) * int(model.tex_height[texture]) * channels
    pixels = np.asarray(model.tex_data[start : start + count], dtype=float).reshape(-1, channels)
    if channels < 3:
        return np.full(3, pixels[:, 0].mean() / 255.0)
    return pixels[:, :3].mean(axis=0) / 255.0


def _shape_kind(model: mujoco.MjModel, geom_id: int) -> str:
    """MuJoCo's geom type as a lower-case name (``box``, ``mesh``, ...)."""
    return mujoco.mjtGeom(int(model.geom_type[geom_id])).name.removeprefix("mjGEOM_").lower()


#: Geom types drawn as instances of one archetype per body (the rest: one Mesh3D per geom).
_BATCHED = {
    "plane": "Boxes3D",
    "box": "Boxes3D",
    "sphere": "Ellipsoids3D",
    "ellipsoid": "Ellipsoids3D",
    "cylinder": "Cylinders3D",
    "capsule": "Capsules3D",
}
_MESHES = ("mesh", "hfield")


def _batched_shape(model: mujoco.MjModel, archetype: str, geoms: list[int]) -> rr.AsComponents:
    """One archetype with an instance per geom, each placed at body_from_geom."""
    sizes = np.array([model.geom_size[g] for g in geoms], dtype=float)
    positions = np.array([model.geom_pos[g] for g in geoms], dtype=float)
    quats_wxyz = np.array([model.geom_quat[g] for g in geoms], dtype=float)
    colours = [geom_rgba(model, g) for g in geoms]
    quaternions = [_xyzw(q) for q in quats_wxyz]
    # Every column costs about 0.7 kB in the file: identity rotations and zero
    # centres are left out (the archetypes' defaults), names are in the entity path,
    # and the solid fill mode is the 3-D view's default (:func:`view_defaults`).
    common: dict[str, Any] = {"colors": colours}  # keyword arguments of several archetypes
    if not np.allclose(quats_wxyz, [1.0, 0.0, 0.0, 0.0]):
        common["quaternions"] = quaternions
    kinds = [_shape_kind(model, g) for g in geoms]
    if archetype == "Boxes3D":
        half = sizes[:, :3].copy()
        centres = positions.copy()
        for row, (kind, q) in enumerate(zip(kinds, quats_wxyz, strict=True)):
            if kind == "plane":  # a thin slab below the plane's surface
                half[row, :2] = [s if s > 0 else _INFINITE_PLANE_HALF_M for s in sizes[row, :2]]
                half[row, 2] = _PLANE_HALF_THICKNESS_M
                centres[row] -= _rotate(q, [0.0, 0.0, _PLANE_HALF_THICKNESS_M])
        return rr.Boxes3D(half_sizes=half, **_centres(centres), **common)
    if archetype == "Ellipsoids3D":
        half = np.where(
            np.array(kinds)[:, None] == "sphere", sizes[:, :1].repeat(3, axis=1), sizes[:, :3]
        )
        return rr.Ellipsoids3D(half_sizes=half, **_centres(positions), **common)
    if archetype == "Cylinders3D":
        return rr.Cylinders3D(
            lengths=2.0 * sizes[:, 1], radii=sizes[:, 0], **_centres(positions), **common
        )
    # Capsules3D: MuJoCo's is centred, half length size[1] along z; Rerun's starts at
    # its translation and runs along +z.
    starts = [
        p - _rotate(q, [0.0, 0.0, s[1]])
        for p, q, s in zip(positions, quats_wxyz, sizes, strict=True)
    ]
    return rr.Capsules3D(
        lengths=2.0 * sizes[:, 1], radii=sizes[:, 0], translations=starts, **common
    )


def _centres(centres: np.ndarray) -> dict[str, Any]:
    """``centers=`` unless all are at the origin (the default)."""
    return {"centers": centres} if np.any(centres) else {}


def _rotate(quat_wxyz: np.ndarray, vector: list[float]) -> np.ndarray:
    """``vector`` rotated by a MuJoCo quaternion."""
    out = np.zeros(3)
    mujoco.mju_rotVecQuat(out, np.asarray(vector, dtype=float), np.asarray(quat_wxyz, dtype=float))
    return out


def _mesh_shape(model: mujoco.MjModel, geom_id: int) -> rr.Mesh3D:
    """A mesh or height-field geom as a Mesh3D in its own frame."""
    colour = geom_rgba(model, geom_id)
    if _shape_kind(model, geom_id) == "hfield":
        vertices, triangles = _hfield_mesh(model, int(model.geom_dataid[geom_id]))
    else:
        mesh = int(model.geom_dataid[geom_id])
        v0, nv = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        f0, nf = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
        vertices = np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=np.float32)
        triangles = np.asarray(model.mesh_face[f0 : f0 + nf], dtype=np.uint32)
    return rr.Mesh3D(vertex_positions=vertices, triangle_indices=triangles, albedo_factor=colour)


def _hfield_mesh(model: mujoco.MjModel, hfield: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (N, 3) and triangles (M, 3) of a height field's top surface."""
    rows, cols = int(model.hfield_nrow[hfield]), int(model.hfield_ncol[hfield])
    sx, sy, sz, _ = (float(v) for v in model.hfield_size[hfield])
    start = int(model.hfield_adr[hfield])
    heights = np.asarray(model.hfield_data[start : start + rows * cols]).reshape(rows, cols)
    x, y = np.meshgrid(np.linspace(-sx, sx, cols), np.linspace(-sy, sy, rows))
    vertices = np.stack([x, y, heights * sz], axis=-1).reshape(-1, 3).astype(np.float32)
    index = np.arange(rows * cols).reshape(rows, cols)
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    c, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    triangles = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)]).astype(np.uint32)
    return vertices, triangles


def _xyzw(quat_wxyz: np.ndarray) -> list[float]:
    """MuJoCo's (w, x, y, z) quaternion as Rerun's (x, y, z, w)."""
    w, x, y, z = (float(v) for v in quat_wxyz)
    return [x, y, z, w]


def log_model_geometry(
    rec: rr.RecordingStream,
    model: mujoco.MjModel,
    root: str = ROOT,
    *,
    static: bool = True,
    textured: bool = False,
) -> ModelGeometry:
    """Log every visible geom of ``model`` once under its body's entity path.

    Primitive geoms of one body are instances of one archetype per kind
    (``ROOT/<body>/boxes``, ``.../ellipsoids``, ``.../cylinders``,
    ``.../capsules``; hover shows each geom's name); a mesh or height field is
    a Mesh3D at ``ROOT/<body>/<geom>`` with its Transform3D body_from_geom.
    ``static=False`` logs them at the stream's current time instead.  ``textured``: a
    plane, box, cylinder or sphere with an RGB texture is a Mesh3D carrying it
    (:mod:`headsim.runs.mjcf_textures`) at ``ROOT/<body>/<geom>``, as a mesh is.
    """
    logged: list[LoggedGeom] = []
    invisible: list[str] = []
    skipped: list[tuple[str, str]] = []
    batches: dict[tuple[int, str], list[int]] = {}
    for geom_id in range(model.ngeom):
        name = geom_name(model, geom_id)
        kind = _shape_kind(model, geom_id)
        if geom_rgba(model, geom_id)[3] <= 0.0:
            invisible.append(name)
        elif (
            textured and kind in TEXTURED_KINDS and _log_textured(rec, model, geom_id, root, static)
        ):
            body_id = int(model.geom_bodyid[geom_id])
            path = f"{body_path(model, body_id, root)}/{rr.escape_entity_path_part(name)}"
            logged.append(LoggedGeom(path, name, body_name(model, body_id), kind, "Mesh3D"))
        elif kind in _BATCHED:
            batches.setdefault((int(model.geom_bodyid[geom_id]), _BATCHED[kind]), []).append(
                geom_id
            )
        elif kind in _MESHES:
            body_id = int(model.geom_bodyid[geom_id])
            path = f"{body_path(model, body_id, root)}/{rr.escape_entity_path_part(name)}"
            rec.log(
                path,
                rr.Transform3D(
                    translation=model.geom_pos[geom_id],
                    quaternion=rr.Quaternion(xyzw=_xyzw(model.geom_quat[geom_id])),
                ),
                _mesh_shape(model, geom_id),
                static=static,
            )
            logged.append(LoggedGeom(path, name, body_name(model, body_id), kind, "Mesh3D"))
        else:
            skipped.append((name, f"geom type {kind} has no Rerun shape"))
    for (body_id, archetype), geoms in sorted(batches.items()):
        names = [geom_name(model, g) for g in geoms]
        path = f"{body_path(model, body_id, root)}/{_ENTITY[archetype]}"
        rec.log(path, _batched_shape(model, archetype, geoms), static=static)
        logged += [
            LoggedGeom(path, n, body_name(model, body_id), _shape_kind(model, g), archetype)
            for g, n in zip(geoms, names, strict=True)
        ]
    return ModelGeometry(tuple(logged), tuple(invisible), tuple(skipped))


def _log_textured(
    rec: rr.RecordingStream, model: mujoco.MjModel, geom_id: int, root: str, static: bool
) -> bool:
    """Log the geom as a textured Mesh3D with its body_from_geom; False if it has no texture."""
    material = int(model.geom_matid[geom_id])
    rgba = model.mat_rgba[material] if material >= 0 else model.geom_rgba[geom_id]
    mesh = textured_mesh(model, geom_id, np.asarray(rgba, dtype=float))
    if mesh is None:
        return False
    body = body_path(model, int(model.geom_bodyid[geom_id]), root)
    rec.log(
        f"{body}/{rr.escape_entity_path_part(geom_name(model, geom_id))}",
        rr.Transform3D(
            translation=model.geom_pos[geom_id],
            quaternion=rr.Quaternion(xyzw=_xyzw(model.geom_quat[geom_id])),
        ),
        mesh,
        static=static,
    )
    return True


_ENTITY = {
    "Boxes3D": "boxes",
    "Ellipsoids3D": "ellipsoids",
    "Cylinders3D": "cylinders",
    "Capsules3D": "capsules",
}


def view_defaults() -> list[rr.AsComponents]:
    """Component defaults for a Spatial3DView that shows the geometry: solid shapes."""
    solid = rr.components.FillMode.Solid
    return [
        rr.Boxes3D.from_fields(fill_mode=solid),
        rr.Ellipsoids3D.from_fields(fill_mode=solid),
        rr.Cylinders3D.from_fields(fill_mode=solid),
        rr.Capsules3D.from_fields(fill_mode=solid),
    ]


class BodyPoses:
    """Logs world_from_body of each body that carries a logged geom, when it moved."""

    def __init__(self, model: mujoco.MjModel, root: str = ROOT) -> None:
        visible = {
            int(model.geom_bodyid[g]) for g in range(model.ngeom) if geom_rgba(model, g)[3] > 0.0
        }
        # The world body is the root's own frame: no transform to log.
        self.bodies = tuple(sorted(visible - {0}))
        self.paths = {b: body_path(model, b, root) for b in self.bodies}
        self._last: dict[int, np.ndarray] = {}

    def moved(self, data: mujoco.MjData) -> list[tuple[str, np.ndarray, list[float]]]:
        """(path, translation, quaternion xyzw) of the bodies whose pose changed since the
        last call (all on the first)."""
        rows = []
        for body in self.bodies:
            pose = np.concatenate([data.xpos[body], data.xquat[body]])
            last = self._last.get(body)
            if last is not None and np.array_equal(last, pose):
                continue
            self._last[body] = pose
            rows.append((self.paths[body], pose[:3], _xyzw(pose[3:])))
        return rows

    def log(self, rec: rr.RecordingStream, data: mujoco.MjData) -> int:
        """Log the bodies whose pose changed since the last call (all on the first); returns how many."""
        rows = self.moved(data)
        for path, translation, xyzw in rows:
            rec.log(
                path, rr.Transform3D(translation=translation, quaternion=rr.Quaternion(xyzw=xyzw))
            )
        return len(rows)


__all__ = [
    "ROOT",
    "BodyPoses",
    "LoggedGeom",
    "ModelGeometry",
    "body_name",
    "body_path",
    "geom_name",
    "geom_rgba",
    "log_model_geometry",
    "view_defaults",
]
