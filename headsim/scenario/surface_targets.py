"""Targets without markers, the truth side: a point on a textured surface, where it
truly is, whether camera 1 sees it at the start, and the click that tells the head.

A target is a point on an object (its name and a point in its frame), or a world point
that lies on a surface (within :data:`ON_SURFACE_M`, else refused with the reason).
Its true position follows from the object's pose.  The head learns of it only as a
user would tell a real head: :func:`click` gives its pixel in camera 1's first image
(the true projection at the start pose plus a click error drawn from the seed).
Random targets are drawn on the surfaces the start pose sees (:func:`draw_targets`),
refused ones drawn again and counted by cause.

Truth, for placing and scoring only (never imported by the servos, the tracker or the
correspondence: tests/active/test_scene_changes.py).  Points in W, m.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from headsim.scenario.reach import ReachHead, target_refusal
from headsim.sim import names
from headsim.sim.simulator import HeadSim

#: How near a surface a world point must lie to be a point on it, m.
ON_SURFACE_M = 1e-3
#: The click error's default standard deviation, px (each axis).
CLICK_ERROR_PX = 0.5
#: Why a random surface target is drawn again: its ray met nothing (or the head); its
#: depth is outside the range; a camera's line of sight meets something else first;
#: camera 1's start image does not show it; the head cannot fixate it (the reach check).
SURFACE_REFUSALS = ("no_surface", "depth", "occluded", "start_view", "reach")
#: The geom groups a cast ray may hit: all but the head's own.
SCENE_GROUPS = np.array([g != names.HEAD_VISUAL_GROUP for g in range(6)], dtype=np.uint8)


class SceneState(Protocol):
    """A compiled scene at a state: a :class:`HeadSim`, or a room's model alone."""

    @property
    def model(self) -> mujoco.MjModel: ...

    @property
    def data(self) -> mujoco.MjData: ...


class NotOnSurface(ValueError):
    """A world point given as a target lies on no surface of the scene."""


def cast(
    model: mujoco.MjModel, data: mujoco.MjData, origin_world_m: np.ndarray, direction: np.ndarray
) -> tuple[np.ndarray | None, float, int]:
    """The first scene geom (not the head's) along a ray: (point in W or None, distance
    along the unit ``direction``, geom id or -1)."""
    direction = np.asarray(direction, dtype=float)
    direction = direction / float(np.linalg.norm(direction))
    origin = np.asarray(origin_world_m, dtype=float)
    geom = np.array([-1], dtype=np.int32)
    distance = mujoco.mj_ray(model, data, origin, direction, SCENE_GROUPS, 1, -1, geom)
    if geom[0] < 0 or distance < 0:
        return None, math.inf, -1
    return origin + distance * direction, float(distance), int(geom[0])


def _box_distance(q: np.ndarray) -> float:
    """Unsigned distance to the surface of a box (or rectangle) from ``q`` = |p| - half."""
    outside = float(np.linalg.norm(np.maximum(q, 0.0)))
    inside = min(float(np.max(q)), 0.0)
    return abs(outside + inside)


def triangle_distance_m(point_m: np.ndarray, triangles_m: np.ndarray) -> float:
    """Distance of a point from the nearest of triangles (T, 3, 3), m (one frame)."""
    p = np.asarray(point_m, dtype=float)
    a, b, c = (np.asarray(triangles_m, dtype=float)[:, k] for k in range(3))
    ab, ac, ap = b - a, c - a, p - a
    n = np.cross(ab, ac)
    area2 = np.einsum("ij,ij->i", n, n)
    # Barycentric coordinates of the projection into each triangle's plane.
    w_c = np.einsum("ij,ij->i", np.cross(ab, ap), n) / area2
    w_b = np.einsum("ij,ij->i", np.cross(ap, ac), n) / area2
    inside = (w_b >= 0) & (w_c >= 0) & (w_b + w_c <= 1)
    plane = np.abs(np.einsum("ij,ij->i", ap, n)) / np.sqrt(area2)
    best = float(plane[inside].min()) if inside.any() else math.inf
    for s, e in ((a, b), (b, c), (c, a)):  # else the nearest point lies on an edge
        d = e - s
        t = np.clip(np.einsum("ij,ij->i", p - s, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
        best = min(best, float(np.linalg.norm(s + t[:, None] * d - p, axis=1).min()))
    return best


def mesh_triangles_m(model: mujoco.MjModel, geom: int) -> np.ndarray:
    """A mesh geom's triangles (T, 3, 3) in the geom's frame, m (MuJoCo's processed mesh)."""
    mesh = int(model.geom_dataid[geom])
    v0, nv = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    f0, nf = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
    vertices = np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=float)
    return vertices[np.asarray(model.mesh_face[f0 : f0 + nf], dtype=int)]


def surface_distance_m(geom_type: int, size: Sequence[float], point_geom_m: np.ndarray) -> float:
    """Distance of a point, in a geom's frame, from its surface, m: a plane (a bounded
    rectangle; size 0: unbounded), sphere, box or cylinder (MuJoCo's sizes); a mesh's is
    :func:`triangle_distance_m` over :func:`mesh_triangles_m`."""
    p = np.asarray(point_geom_m, dtype=float)
    if geom_type == mujoco.mjtGeom.mjGEOM_PLANE:
        a, b = size[0], size[1]
        dx = max(abs(p[0]) - a, 0.0) if a > 0 else 0.0
        dy = max(abs(p[1]) - b, 0.0) if b > 0 else 0.0
        return math.sqrt(dx * dx + dy * dy + p[2] * p[2])
    if geom_type == mujoco.mjtGeom.mjGEOM_SPHERE:
        return abs(float(np.linalg.norm(p)) - size[0])
    if geom_type == mujoco.mjtGeom.mjGEOM_BOX:
        return _box_distance(np.abs(p) - np.asarray(size[:3], dtype=float))
    if geom_type == mujoco.mjtGeom.mjGEOM_CYLINDER:
        q = np.array([math.hypot(p[0], p[1]) - size[0], abs(p[2]) - size[1]])
        return _box_distance(q)
    raise ValueError(f"no surface distance for geom type {geom_type}")


@dataclass(frozen=True)
class SurfaceTarget:
    """A target point on a surface: the ``body`` (and geom) it lies on, the point in the
    body's frame ``point_body_m`` and in W ``point_world_m`` (m), as placed;
    ``texture_class`` for the by-texture table ("": not yet classed)."""

    name: str
    body: str
    point_body_m: tuple[float, float, float]
    point_world_m: tuple[float, float, float]
    texture_class: str = ""


def _triple(p: np.ndarray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))


def point_world(sim: SceneState, body: str, point_body_m: ArrayLike) -> np.ndarray:
    """Where a point given in ``body``'s frame truly is now, W, m."""
    b = sim.data.body(body)
    return np.asarray(b.xpos + b.xmat.reshape(3, 3) @ np.asarray(point_body_m, dtype=float))


def _scene_geoms(model: mujoco.MjModel) -> list[int]:
    types = (
        mujoco.mjtGeom.mjGEOM_PLANE,
        mujoco.mjtGeom.mjGEOM_SPHERE,
        mujoco.mjtGeom.mjGEOM_BOX,
        mujoco.mjtGeom.mjGEOM_CYLINDER,
        mujoco.mjtGeom.mjGEOM_MESH,
    )
    return [
        g
        for g in range(model.ngeom)
        if int(model.geom_group[g]) != names.HEAD_VISUAL_GROUP and int(model.geom_type[g]) in types
    ]


def surface_of(sim: SceneState, point_world_m: ArrayLike) -> tuple[int, float]:
    """The scene geom whose surface is nearest a world point, and the distance, m."""
    p = np.asarray(point_world_m, dtype=float)
    best, best_d = -1, math.inf
    for g in _scene_geoms(sim.model):
        local = sim.data.geom_xmat[g].reshape(3, 3).T @ (p - sim.data.geom_xpos[g])
        if int(sim.model.geom_type[g]) == mujoco.mjtGeom.mjGEOM_MESH:
            d = triangle_distance_m(local, mesh_triangles_m(sim.model, g))
        else:
            d = surface_distance_m(int(sim.model.geom_type[g]), sim.model.geom_size[g], local)
        if d < best_d:
            best, best_d = g, d
    return best, best_d


def surface_normal(sim: SceneState, point_world_m: ArrayLike) -> np.ndarray:
    """The outward unit normal, in W, of the scene surface nearest a point on it (a plane's
    front, a sphere's radius, a box's face, a cylinder's side or cap, a mesh's nearest
    face)."""
    p = np.asarray(point_world_m, dtype=float)
    geom, _ = surface_of(sim, p)
    if geom < 0:
        raise NotOnSurface("no surface in the scene")
    rotation = sim.data.geom_xmat[geom].reshape(3, 3)
    local = rotation.T @ (p - sim.data.geom_xpos[geom])
    size = sim.model.geom_size[geom]
    kind = int(sim.model.geom_type[geom])
    if kind == mujoco.mjtGeom.mjGEOM_PLANE:
        normal = np.array([0.0, 0.0, 1.0])
    elif kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        normal = local
    elif kind == mujoco.mjtGeom.mjGEOM_MESH:
        triangles = mesh_triangles_m(sim.model, geom)
        nearest = int(np.argmin([triangle_distance_m(local, t[None]) for t in triangles]))
        a, b, c = triangles[nearest]
        normal = np.cross(b - a, c - a)
    elif kind == mujoco.mjtGeom.mjGEOM_BOX:
        axis = int(np.argmax(np.abs(local) - size[:3]))
        normal = np.zeros(3)
        normal[axis] = 1.0 if local[axis] >= 0 else -1.0
    else:  # a cylinder: its side or a cap, whichever the point lies on
        radial = math.hypot(local[0], local[1])
        if abs(local[2]) - size[1] > radial - size[0]:
            normal = np.array([0.0, 0.0, 1.0 if local[2] >= 0 else -1.0])
        else:
            normal = np.array([local[0], local[1], 0.0])
    world = rotation @ normal
    return np.asarray(world / float(np.linalg.norm(world)))


def on_object(sim: SceneState, name: str, body: str, point_body_m: ArrayLike) -> SurfaceTarget:
    """A target at ``point_body_m`` on ``body``, checked to lie on its surface."""
    if mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, body) < 0:
        raise NotOnSurface(f"{name}: no object named {body!r} in the scene")
    p = point_world(sim, body, point_body_m)
    geom, distance = surface_of(sim, p)
    if geom < 0 or sim.model.body(int(sim.model.geom_bodyid[geom])).name != body:
        raise NotOnSurface(f"{name}: the point is nearer another object's surface than {body!r}'s")
    if distance > ON_SURFACE_M:
        raise NotOnSurface(
            f"{name}: the point lies {distance * 1e3:.1f} mm from {body!r}'s surface "
            f"(allowed: within {ON_SURFACE_M * 1e3:g} mm)"
        )
    return SurfaceTarget(name, body, _triple(np.asarray(point_body_m, dtype=float)), _triple(p))


def on_surface(sim: SceneState, name: str, point_world_m: ArrayLike) -> SurfaceTarget:
    """A target at a world point, checked to lie within :data:`ON_SURFACE_M` of a surface."""
    p = np.asarray(point_world_m, dtype=float)
    geom, distance = surface_of(sim, p)
    if geom < 0 or distance > ON_SURFACE_M:
        raise NotOnSurface(
            f"{name}: the point lies {distance * 1e3:.1f} mm from the nearest surface "
            f"(allowed: within {ON_SURFACE_M * 1e3:g} mm of one)"
        )
    body = int(sim.model.geom_bodyid[geom])
    b = sim.data.body(body)
    local = b.xmat.reshape(3, 3).T @ (p - b.xpos)
    return SurfaceTarget(name, sim.model.body(body).name, _triple(local), _triple(p))


def camera_centre(sim: HeadSim, camera: int) -> np.ndarray:
    """Camera ``camera``'s (1, 2) true optical centre now, W, m."""
    return sim.truth.world_from_camera(camera)[:3, 3].copy()


def visible(sim: HeadSim, camera: int, point_world_m: ArrayLike) -> bool:
    """Whether camera ``camera``'s (1, 2) line of sight to the point, from its true centre
    now, first meets the scene at the point (within :data:`ON_SURFACE_M`)."""
    p = np.asarray(point_world_m, dtype=float)
    origin = camera_centre(sim, camera)
    hit, _, _ = cast(sim.model, sim.data, origin, p - origin)
    return hit is not None and float(np.linalg.norm(hit - p)) <= ON_SURFACE_M


@dataclass(frozen=True)
class Click:
    """A user's click on a target in camera 1's first image: the true projection
    ``true_uv`` and the ``clicked_uv`` the head is told (px, OpenCV's), ``error_px`` the
    click error's standard deviation."""

    true_uv: tuple[float, float]
    clicked_uv: tuple[float, float]
    error_px: float


def click(
    sim: HeadSim,
    point_world_m: ArrayLike,
    rng: np.random.Generator,
    error_px: float = CLICK_ERROR_PX,
) -> Click:
    """The click on a target in camera 1's image at the simulator's pose now (call it at
    the start pose, once): its true projection plus a normal error of ``error_px`` per
    axis drawn from ``rng``."""
    true_uv = sim.truth.project(np.asarray(point_world_m, dtype=float)[None, :], 1)[0]
    clicked = true_uv + rng.normal(0.0, error_px, 2) if error_px > 0 else true_uv
    return Click(
        (float(true_uv[0]), float(true_uv[1])), (float(clicked[0]), float(clicked[1])), error_px
    )


@dataclass(frozen=True)
class DrawnTargets:
    """Random surface targets and how they were drawn: ``drawn`` draws in all, the
    ``refused`` ones by cause (:data:`SURFACE_REFUSALS`), each drawn again."""

    targets: tuple[SurfaceTarget, ...]
    drawn: int
    refused: dict[str, int]


def in_image(sim: HeadSim, camera: int, p: np.ndarray, margin_px: float = 0.0) -> bool:
    """Whether the point projects into ``camera``'s image at least ``margin_px`` inside."""
    cam = sim.camera_settings(camera)
    if sim.truth.transform_points(p, "world", names.CAMERAS[camera - 1])[0][2] <= 0:
        return False
    u, v = sim.truth.project(p[None, :], camera)[0]
    m = margin_px
    return bool(m <= u <= cam.width - 1 - m and m <= v <= cam.height - 1 - m)


def surface_refusal(
    sim: HeadSim,
    p: np.ndarray | None,
    depth_m: tuple[float, float],
    head: ReachHead | None,
    margin_px: float = 0.0,
    margin2_px: float | None = None,
) -> str | None:
    """Why a point met on a surface is no target (:data:`SURFACE_REFUSALS`), or None;
    ``margin_px``: how far inside camera 1's start image it must be (a template's room);
    ``margin2_px``: how far inside camera 2's (None: camera 2 need only see it)."""
    if p is None:
        return "no_surface"
    depth = float(sim.truth.transform_points(p, "world", "head")[0][2])
    if not depth_m[0] <= depth <= depth_m[1]:
        return "depth"
    if not (visible(sim, 1, p) and visible(sim, 2, p)):
        return "occluded"
    if not in_image(sim, 1, p, margin_px):
        return "start_view"
    if margin2_px is not None and not in_image(sim, 2, p, margin2_px):
        return "start_view"
    if head is not None and target_refusal(head, "model2", p) is not None:
        return "reach"
    return None


def draw_targets(
    sim: HeadSim,
    count: int,
    rng: np.random.Generator,
    depth_m: tuple[float, float] = (0.3, 2.0),
    lateral: float = 0.25,
    vertical: float = 0.1,
    max_draws: int = 200,
    margin_px: float = 0.0,
    margin2_px: float | None = None,
) -> DrawnTargets:
    """``count`` targets on the surfaces the head sees at its pose now (call it at the
    start pose): a direction in H with |x/z| <= ``lateral`` and |y/z| <= ``vertical``
    from the midpoint of the two cameras, cast into the scene; a point met is kept when
    :func:`surface_refusal` finds nothing wrong (``margin_px`` inside camera 1's image,
    ``margin2_px`` inside camera 2's unless None), else drawn again (counted by cause)."""
    origin = (camera_centre(sim, 1) + camera_centre(sim, 2)) / 2
    world_from_head = sim.truth.world_from_head()[:3, :3]
    head = ReachHead.of(sim.truth.settings)
    refused: dict[str, int] = {}
    out: list[SurfaceTarget] = []
    drawn = 0
    while len(out) < count:
        if drawn >= max_draws * count:
            raise ValueError(
                f"no surface point the head can fixate in {drawn} draws; refused: {refused}"
            )
        drawn += 1
        x, y = rng.uniform(-lateral, lateral), rng.uniform(-vertical, vertical)
        hit, _, _ = cast(sim.model, sim.data, origin, world_from_head @ np.array([x, y, 1.0]))
        reason = surface_refusal(sim, hit, depth_m, head, margin_px, margin2_px)
        if reason is not None:
            refused[reason] = refused.get(reason, 0) + 1
            continue
        assert hit is not None
        out.append(on_surface(sim, f"surface_{len(out) + 1}", hit))
    return DrawnTargets(tuple(out), drawn, dict(sorted(refused.items(), key=lambda kv: -kv[1])))


__all__ = [
    "CLICK_ERROR_PX",
    "ON_SURFACE_M",
    "SURFACE_REFUSALS",
    "Click",
    "DrawnTargets",
    "NotOnSurface",
    "SceneState",
    "SurfaceTarget",
    "camera_centre",
    "cast",
    "click",
    "draw_targets",
    "in_image",
    "mesh_triangles_m",
    "on_object",
    "on_surface",
    "point_world",
    "surface_distance_m",
    "surface_normal",
    "surface_of",
    "surface_refusal",
    "triangle_distance_m",
    "visible",
]
