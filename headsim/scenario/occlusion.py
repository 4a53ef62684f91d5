"""What of a scene can hide a target from an eye: its geoms (a sphere, another shape's
bounding sphere, or a plane) where the scene's XML or earlier placements put them, and
whether one lies in a line of sight.  Geometry only, no rendering; placement and
checks use it (the truth), never a measurement.  Points in W, m.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import mujoco
import numpy as np

from headsim.sim import names
from headsim.sim.heads import PAPER, HeadModel
from headsim.sim.model import load_spec


@cache
def scene_model(scene: str, head: HeadModel = PAPER) -> mujoco.MjModel:
    """The compiled scene as in the XML (joint ranges, default poses), with ``head``;
    no rendering."""
    return load_spec(scene, head).compile()


@dataclass(frozen=True)
class Occluder:
    """A geom of the scene that can hide a target: a sphere (or another shape's bounding
    sphere), or a plane (``normal``, ``axes`` its x and y, ``half`` its half-sizes, 0: unbounded)."""

    name: str
    body: str
    plane: bool
    centre: np.ndarray
    radius: float
    normal: np.ndarray
    axes: np.ndarray
    half: tuple[float, float]


@cache
def _scene_occluders(scene: str) -> tuple[Occluder, ...]:
    """Every geom of ``scene`` an eye camera draws (not the head's), where the XML puts it."""
    model = scene_model(scene)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    out = []
    for g in range(model.ngeom):
        if int(model.geom_group[g]) == names.HEAD_VISUAL_GROUP:
            continue
        rotation = data.geom_xmat[g].reshape(3, 3)
        plane = int(model.geom_type[g]) == int(mujoco.mjtGeom.mjGEOM_PLANE)
        sphere = int(model.geom_type[g]) == int(mujoco.mjtGeom.mjGEOM_SPHERE)
        out.append(
            Occluder(
                name=model.geom(g).name or f"geom {g}",
                body=model.body(int(model.geom_bodyid[g])).name,
                plane=plane,
                centre=data.geom_xpos[g].copy(),
                radius=float(model.geom_size[g][0] if sphere else model.geom_rbound[g]),
                normal=rotation[:, 2].copy(),
                axes=rotation[:, :2].copy(),
                half=(float(model.geom_size[g][0]), float(model.geom_size[g][1])),
            )
        )
    return tuple(out)


def scene_occluders(
    scene: str, placed: dict[str, np.ndarray] | None = None, target_body: str | None = None
) -> tuple[Occluder, ...]:
    """The geoms that can hide a target of body ``target_body`` in ``scene``: every geom but
    the head's and the target's own, the bodies in ``placed`` moved to their world
    positions, m (where earlier placements left them), the others where the XML puts them."""
    base = _scene_occluders(scene)
    model = scene_model(scene)
    out = []
    for o in base:
        if o.body == target_body:
            continue
        if placed and o.body in placed:
            offset = o.centre - model.body(o.body).pos
            o = Occluder(
                o.name, o.body, o.plane, np.asarray(placed[o.body]) + offset,
                o.radius, o.normal, o.axes, o.half,
            )  # fmt: skip
        out.append(o)
    return tuple(out)


def hidden_by(
    eye_world: np.ndarray,
    point_world: np.ndarray,
    radius_m: float,
    margin_rad: float,
    occluders: tuple[Occluder, ...],
) -> str | None:
    """The geom that hides (any of) a ball of ``radius_m`` at ``point_world`` from an eye at
    ``eye_world``, or None: a sphere nearer than the point whose disc comes within
    ``margin_rad`` of the ball's, or a plane that the line of sight crosses."""
    d = np.asarray(point_world, dtype=float) - eye_world
    length = float(np.linalg.norm(d))
    u = d / length
    for o in occluders:
        if o.plane:
            se = float(o.normal @ (eye_world - o.centre))
            sp = float(o.normal @ (point_world - o.centre))
            if se * sp >= 0.0:
                continue
            local = o.axes.T @ (eye_world + d * se / (se - sp) - o.centre)
            if all(h <= 0.0 or abs(x) <= h for x, h in zip(local, o.half, strict=True)):
                return o.name
            continue
        t = float((o.centre - eye_world) @ u)
        if t <= 0.0 or t >= length:
            continue  # behind the eye, or beyond the point
        miss = float(np.linalg.norm(o.centre - eye_world - t * u))
        if miss < o.radius + t * (radius_m / length + margin_rad):
            return o.name
    return None


__all__ = ["Occluder", "hidden_by", "scene_model", "scene_occluders"]
