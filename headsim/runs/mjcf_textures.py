"""A MuJoCo model's textured primitives as Rerun meshes that carry their texture.

:mod:`headsim.runs.mjcf_rerun` draws primitives in one colour each (a texture as its
mean colour); for a room (:mod:`headsim.sim.textured_scene`) the texture is what the
eyes correlate on, so :func:`textured_mesh` turns a plane, box, cylinder or sphere
whose material has an RGB texture into a ``Mesh3D`` in the geom's frame, with texture
coordinates and the texture image (from the compiled model's ``tex_data``, scaled down
to at most :data:`MAX_TEXTURE_PX` a side to keep the file small).

The mapping follows MuJoCo's where it matters and approximates it elsewhere:

- a plane with a 2-D texture repeats it ``texrepeat`` times over its sides (``texuniform``
  off, as the room sets it): column j along +x, row 0 at the +y edge; each repeat is a
  quad of its own, so texture coordinates stay in [0, 1] (no wrapping asked of the viewer);
- a box shows the image once on each face (a cube texture of one image), upright on the
  side faces;
- a cylinder's side shows it four times around and once over its height, each cap once;
  a sphere's four times around and twice from pole to pole (MuJoCo projects the cube map,
  which these approximate: the viewer's picture, not the camera's);
- a mesh takes its own texture coordinates, each face's moved by whole tiles to start
  at 0 (the viewer does not wrap them; a face wider than a tile is clamped).

Pure geometry apart from reading the model; positions in the geom's frame, m.
"""

from __future__ import annotations

import math

import cv2
import mujoco
import numpy as np
import rerun as rr

#: The longest side of a texture image in the recording, px (the room's are 256).
MAX_TEXTURE_PX = 128
#: Segments around a cylinder or sphere (a multiple of 4: four repeats around) and bands
#: from pole to pole of a sphere (even: two repeats).
AROUND = 32
BANDS = 16
#: The shapes drawn textured.
TEXTURED_KINDS = ("plane", "box", "cylinder", "sphere", "mesh")

Mesh = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # positions, normals, uv, triangles


def texture_id(model: mujoco.MjModel, geom_id: int) -> int:
    """The RGB texture the geom's material uses (2-D or cube), -1 if none."""
    material = int(model.geom_matid[geom_id])
    if material < 0:
        return -1
    texture = int(model.mat_texid[material][int(mujoco.mjtTextureRole.mjTEXROLE_RGB)])
    if texture < 0 or int(model.tex_type[texture]) == int(mujoco.mjtTexture.mjTEXTURE_SKYBOX):
        return -1
    return texture


def texture_image(model: mujoco.MjModel, texture: int, max_px: int = MAX_TEXTURE_PX) -> np.ndarray:
    """The texture's first square image, RGB uint8 (H, W, 3), at most ``max_px`` a side
    (a cube texture of one image holds it once per face: the first is the image)."""
    width, height = int(model.tex_width[texture]), int(model.tex_height[texture])
    channels = int(model.tex_nchannel[texture])
    rows = min(height, width) if int(model.tex_type[texture]) != 0 else height
    start = int(model.tex_adr[texture])
    pixels = np.asarray(model.tex_data[start : start + rows * width * channels], dtype=np.uint8)
    image = pixels.reshape(rows, width, channels)
    if channels == 1:
        image = np.repeat(image, 3, axis=2)
    rgb = np.ascontiguousarray(image[:, :, :3])
    if max(rows, width) > max_px:
        scale = max_px / max(rows, width)
        size = (max(round(width * scale), 1), max(round(rows * scale), 1))
        return np.asarray(cv2.resize(rgb, size, interpolation=cv2.INTER_AREA), dtype=np.uint8)
    return rgb


def _quads(corners: np.ndarray, normals: np.ndarray, uv: np.ndarray) -> Mesh:
    """Quads (Q, 4, 3) corners (top-left, top-right, bottom-right, bottom-left as seen
    from the outside, the way the normal points), (Q, 3) normals and (Q, 4, 2) texture
    coordinates, each two triangles of its own four vertices (so texture coordinates
    never wrap), counter-clockwise seen from the outside: Rerun's front faces."""
    count = len(corners)
    base = 4 * np.arange(count, dtype=np.uint32)[:, None, None]
    triangles = (np.array([[0, 2, 1], [0, 3, 2]], dtype=np.uint32) + base).reshape(-1, 3)
    return (
        np.asarray(corners, dtype=np.float32).reshape(-1, 3),
        np.repeat(np.asarray(normals, dtype=np.float32), 4, axis=0),
        np.asarray(uv, dtype=np.float32).reshape(-1, 2),
        triangles,
    )


def _uv4(*corners: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Four corners' (u, v), each a pair of arrays over the quads: (Q, 4, 2)."""
    return np.stack([np.stack(uv, -1) for uv in corners], axis=1)


def _join(*meshes: Mesh) -> Mesh:
    offsets = np.cumsum([0] + [len(m[0]) for m in meshes[:-1]]).astype(np.uint32)
    return (
        np.concatenate([m[0] for m in meshes]),
        np.concatenate([m[1] for m in meshes]),
        np.concatenate([m[2] for m in meshes]),
        np.concatenate([m[3] + o for m, o in zip(meshes, offsets, strict=True)]),
    )


def _cells(count: int, per: int) -> tuple[np.ndarray, np.ndarray]:
    """Each of ``count`` cells' texture coordinate start and end, ``per`` cells per repeat."""
    k = np.arange(count) % per
    return k / per, (k + 1) / per


def plane_mesh(half_x_m: float, half_y_m: float, repeat: tuple[float, float]) -> Mesh:
    """A plane's quads, one per texture repeat (the last one cut): u along +x, row 0 at +y."""
    rx, ry = max(float(repeat[0]), 1e-6), max(float(repeat[1]), 1e-6)
    i = np.arange(math.ceil(rx - 1e-9), dtype=float)
    j = np.arange(math.ceil(ry - 1e-9), dtype=float)
    ii, jj = (a.ravel() for a in np.meshgrid(i, j, indexing="ij"))
    u1, v1 = np.minimum(ii + 1.0, rx), np.minimum(jj + 1.0, ry)
    x0, x1 = -half_x_m + 2 * half_x_m * ii / rx, -half_x_m + 2 * half_x_m * u1 / rx
    y0, y1 = half_y_m - 2 * half_y_m * jj / ry, half_y_m - 2 * half_y_m * v1 / ry
    zero = np.zeros_like(x0)
    corners = np.stack(
        [
            np.stack([x0, y0, zero], -1),
            np.stack([x1, y0, zero], -1),
            np.stack([x1, y1, zero], -1),
            np.stack([x0, y1, zero], -1),
        ],
        axis=1,
    )
    du, dv = u1 - ii, v1 - jj
    uv = _uv4((zero, zero), (du, zero), (du, dv), (zero, dv))
    normals = np.tile([0.0, 0.0, 1.0], (len(corners), 1))
    return _quads(corners, normals, uv)


def box_mesh(half_m: np.ndarray) -> Mesh:
    """A box's six faces, the whole image on each (upright on the side faces)."""
    hx, hy, hz = (float(h) for h in half_m)
    corners = np.array(  # top-left, top-right, bottom-right, bottom-left
        [
            [[-hx, -hy, hz], [hx, -hy, hz], [hx, -hy, -hz], [-hx, -hy, -hz]],
            [[hx, hy, hz], [-hx, hy, hz], [-hx, hy, -hz], [hx, hy, -hz]],
            [[hx, -hy, hz], [hx, hy, hz], [hx, hy, -hz], [hx, -hy, -hz]],
            [[-hx, hy, hz], [-hx, -hy, hz], [-hx, -hy, -hz], [-hx, hy, -hz]],
            [[-hx, hy, hz], [hx, hy, hz], [hx, -hy, hz], [-hx, -hy, hz]],
            [[-hx, -hy, -hz], [hx, -hy, -hz], [hx, hy, -hz], [-hx, hy, -hz]],
        ]
    )
    normals = np.array([[0, -1, 0], [0, 1, 0], [1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1]])
    uv = np.tile(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float), (6, 1, 1))
    return _quads(corners, normals.astype(float), uv)


def cylinder_mesh(radius_m: float, half_height_m: float, around: int = AROUND) -> Mesh:
    """A cylinder along z: the side (the image four times around), then both caps."""
    a0 = 2 * np.pi * np.arange(around) / around
    a1 = a0 + 2 * np.pi / around
    c0, s0, c1, s1 = np.cos(a0), np.sin(a0), np.cos(a1), np.sin(a1)
    h = np.full(around, half_height_m)
    r = radius_m
    side = np.stack(
        [
            np.stack([r * c0, r * s0, h], -1),
            np.stack([r * c1, r * s1, h], -1),
            np.stack([r * c1, r * s1, -h], -1),
            np.stack([r * c0, r * s0, -h], -1),
        ],
        axis=1,
    )
    mid = (a0 + a1) / 2
    side_normals = np.stack([np.cos(mid), np.sin(mid), np.zeros(around)], -1)
    u0, u1 = _cells(around, around // 4)
    zero, one = np.zeros(around), np.ones(around)
    side_uv = _uv4((u0, zero), (u1, zero), (u1, one), (u0, one))
    caps = []
    for sign in (1.0, -1.0):
        # A degenerate quad (centre, rim, rim, centre) is a triangle, its rim clockwise
        # seen from outside.
        xa, ya, xb, yb = (c1, s1, c0, s0) if sign > 0 else (c0, s0, c1, s1)
        z = sign * h
        ring = np.stack(
            [
                np.stack([zero, zero, z], -1),
                np.stack([r * xa, r * ya, z], -1),
                np.stack([r * xb, r * yb, z], -1),
                np.stack([zero, zero, z], -1),
            ],
            axis=1,
        )
        uv = np.stack([(ring[..., 0] / r + 1) / 2, (1 - ring[..., 1] / r) / 2], -1)
        caps.append(_quads(ring, np.tile([0.0, 0.0, sign], (around, 1)), uv))
    return _join(_quads(side, side_normals, side_uv), *caps)


def sphere_mesh(radius_m: float, around: int = AROUND, bands: int = BANDS) -> Mesh:
    """A sphere: the image four times around and twice from pole to pole."""
    j, k = (a.ravel() for a in np.meshgrid(np.arange(bands), np.arange(around), indexing="ij"))
    lat0 = np.pi / 2 - np.pi * j / bands
    lat1 = lat0 - np.pi / bands
    lon0 = 2 * np.pi * k / around
    lon1 = lon0 + 2 * np.pi / around

    def unit(lat: np.ndarray, lon: np.ndarray) -> np.ndarray:
        return np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], -1)

    corners = radius_m * np.stack(
        [unit(lat0, lon0), unit(lat0, lon1), unit(lat1, lon1), unit(lat1, lon0)], axis=1
    )
    normals = unit((lat0 + lat1) / 2, (lon0 + lon1) / 2)
    v0, v1 = _cells(bands, bands // 2)
    u0, u1 = _cells(around, around // 4)
    v0, v1 = v0[j], v1[j]
    u0, u1 = u0[k], u1[k]
    uv = _uv4((u0, v0), (u1, v0), (u1, v1), (u0, v1))
    return _quads(corners, normals, uv)


def mesh_mesh(model: mujoco.MjModel, geom_id: int) -> Mesh:
    """A mesh geom with its own texture coordinates, each face its own three vertices."""
    mesh = int(model.geom_dataid[geom_id])
    v0, f0 = int(model.mesh_vertadr[mesh]), int(model.mesh_faceadr[mesh])
    nf = int(model.mesh_facenum[mesh])
    faces = np.asarray(model.mesh_face[f0 : f0 + nf], dtype=int)
    corners = np.asarray(model.mesh_vert, dtype=float)[v0 + faces]  # F x 3 x 3
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    t0 = int(model.mesh_texcoordadr[mesh])
    uv = np.asarray(model.mesh_texcoord, dtype=float)[
        t0 + np.asarray(model.mesh_facetexcoord[f0 : f0 + nf], dtype=int)
    ]
    uv -= np.floor(uv.min(axis=1, keepdims=True))
    return (
        corners.reshape(-1, 3).astype(np.float32),
        np.repeat(normals, 3, axis=0).astype(np.float32),
        uv.reshape(-1, 2).astype(np.float32),
        np.arange(3 * nf, dtype=np.uint32).reshape(-1, 3),
    )


def textured_mesh(model: mujoco.MjModel, geom_id: int, rgba: np.ndarray) -> rr.Mesh3D | None:
    """The geom as a textured Mesh3D in its own frame, None when it has no RGB texture or
    its shape is not one of :data:`TEXTURED_KINDS`.  ``rgba``: the colour it multiplies
    (the material's: white leaves the texture as it is)."""
    texture = texture_id(model, geom_id)
    if texture < 0:
        return None
    kind = mujoco.mjtGeom(int(model.geom_type[geom_id])).name.removeprefix("mjGEOM_").lower()
    size = np.asarray(model.geom_size[geom_id], dtype=float)
    if kind == "plane":
        material = int(model.geom_matid[geom_id])
        repeat = tuple(float(r) for r in model.mat_texrepeat[material])
        if bool(model.mat_texuniform[material]):  # repeats per metre
            repeat = (repeat[0] * 2 * size[0], repeat[1] * 2 * size[1])
        shape = plane_mesh(size[0] or 1.0, size[1] or 1.0, (repeat[0], repeat[1]))
    elif kind == "box":
        shape = box_mesh(size[:3])
    elif kind == "cylinder":
        shape = cylinder_mesh(size[0], size[1])
    elif kind == "sphere":
        shape = sphere_mesh(size[0])
    elif kind == "mesh":
        shape = mesh_mesh(model, geom_id)
    else:
        return None
    positions, normals, uv, triangles = shape
    return rr.Mesh3D(
        vertex_positions=positions,
        vertex_normals=normals,
        vertex_texcoords=uv,
        triangle_indices=triangles,
        albedo_texture=texture_image(model, texture),
        albedo_factor=np.asarray(rgba, dtype=float),
        # A plane is seen from its front only, as MuJoCo draws it: a 3-D view from
        # outside the room looks through the walls' backs.
        face_rendering="Front" if kind == "plane" else None,
    )


__all__ = [
    "MAX_TEXTURE_PX",
    "TEXTURED_KINDS",
    "box_mesh",
    "cylinder_mesh",
    "mesh_mesh",
    "plane_mesh",
    "sphere_mesh",
    "texture_id",
    "texture_image",
    "textured_mesh",
]
