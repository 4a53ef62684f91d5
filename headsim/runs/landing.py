"""Where the eyes actually landed: each eye's goal ray cast at its true pose into the
scene (``mujoco.mj_ray``), and the angles that score a fixation by it.

This is truth, for scoring and recording only: the servos, the tracker and the
correspondence never import it (tests/active/test_scene_changes.py).  The pure math
(:func:`angle_deg`, :func:`vergence_error_deg`, :func:`fixation_error`) takes plain
points and directions in W, m; :func:`landing` reads the simulator.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from headsim.scenario.surface_targets import cast
from headsim.sim.simulator import CameraId, HeadSim


@dataclass(frozen=True)
class Landing:
    """One eye's goal ray at its true pose and what it hits: ``origin_world_m`` (the
    camera's true centre), unit ``direction_world``, the hit ``point_world_m`` (None:
    nothing), its ``distance_m`` along the ray, and the ``geom``/``body`` hit (names;
    "" when unnamed or nothing)."""

    camera: int
    goal_uv: tuple[float, float]
    origin_world_m: np.ndarray
    direction_world: np.ndarray
    point_world_m: np.ndarray | None
    distance_m: float
    geom: str
    body: str

    @property
    def hit(self) -> bool:
        return self.point_world_m is not None


@dataclass(frozen=True)
class FixationError:
    """An eye's landed point against the intended target: ``angle_deg`` between the goal
    ray and the direction from the eye's centre to the target, and ``distance_m`` of the
    landed point from the target (nan: the ray hit nothing)."""

    angle_deg: float
    distance_m: float


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / float(np.linalg.norm(v))


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    """The angle between directions ``a`` and ``b``, degrees (atan2 of the cross and dot
    products: exact near 0 as well)."""
    a, b = _unit(a), _unit(b)
    return math.degrees(math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b)))


def vergence_error_deg(
    origin2_world_m: np.ndarray, direction2_world: np.ndarray, landed1_world_m: np.ndarray
) -> float:
    """Vergence error, degrees: the angle between eye 2's goal ray and the direction from
    eye 2's centre to the point eye 1 landed on (0: both eyes look at one point)."""
    return angle_deg(direction2_world, np.asarray(landed1_world_m) - origin2_world_m)


def fixation_error(
    origin_world_m: np.ndarray,
    direction_world: np.ndarray,
    landed_world_m: np.ndarray | None,
    target_world_m: np.ndarray,
) -> FixationError:
    """One eye's :class:`FixationError` against ``target_world_m``."""
    target = np.asarray(target_world_m, dtype=float)
    angle = angle_deg(direction_world, target - origin_world_m)
    distance = (
        math.nan if landed_world_m is None else float(np.linalg.norm(landed_world_m - target))
    )
    return FixationError(angle, distance)


def ray_direction_world(sim: HeadSim, camera: CameraId, goal_uv: Sequence[float]) -> np.ndarray:
    """The unit direction in W of the true camera's ray through pixel ``goal_uv`` (lens
    distortion undone exactly), at the camera's true pose now."""
    index = sim.camera_index(camera)
    xy = sim.truth.settings.cameras[index].pinhole().normalise(np.asarray(goal_uv, dtype=float))
    xy = np.asarray(xy, dtype=float).reshape(-1)[:2]
    world_from_cam = sim.truth.world_from_camera(index + 1)
    return _unit(world_from_cam[:3, :3] @ np.array([xy[0], xy[1], 1.0]))


def landing(sim: HeadSim, camera: CameraId, goal_uv: Sequence[float]) -> Landing:
    """Where ``camera``'s ray through ``goal_uv`` (the servo's goal pixel), at the camera's
    true pose now, meets the scene."""
    index = sim.camera_index(camera)
    origin = sim.truth.world_from_camera(index + 1)[:3, 3].copy()
    direction = ray_direction_world(sim, index + 1, goal_uv)
    point, distance, geom = cast(sim.model, sim.data, origin, direction)
    geom_name = body_name = ""
    if geom >= 0:
        geom_name = sim.model.geom(geom).name
        body_name = sim.model.body(int(sim.model.geom_bodyid[geom])).name
    return Landing(
        camera=index + 1,
        goal_uv=(float(goal_uv[0]), float(goal_uv[1])),
        origin_world_m=origin,
        direction_world=direction,
        point_world_m=point,
        distance_m=distance,
        geom=geom_name,
        body=body_name,
    )


@dataclass(frozen=True)
class FixationTruth:
    """Where both eyes landed at a fixation, scored: ``vergence_error_deg`` (nan when eye
    1's ray hit nothing) and each eye's :class:`FixationError` against the target."""

    landings: tuple[Landing, Landing]
    vergence_error_deg: float
    errors: tuple[FixationError, FixationError]


def fixation_truth(
    sim: HeadSim, goal_uv: tuple[Sequence[float], Sequence[float]], target_world_m: np.ndarray
) -> FixationTruth:
    """Both eyes' :class:`Landing` through their goal pixels, at their true poses now,
    scored against the intended ``target_world_m``."""
    one, two = landing(sim, 1, goal_uv[0]), landing(sim, 2, goal_uv[1])
    vergence = (
        math.nan
        if one.point_world_m is None
        else vergence_error_deg(two.origin_world_m, two.direction_world, one.point_world_m)
    )
    errors = tuple(
        fixation_error(x.origin_world_m, x.direction_world, x.point_world_m, target_world_m)
        for x in (one, two)
    )
    return FixationTruth((one, two), vergence, (errors[0], errors[1]))


__all__ = [
    "FixationError",
    "FixationTruth",
    "Landing",
    "angle_deg",
    "fixation_error",
    "fixation_truth",
    "landing",
    "ray_direction_world",
    "vergence_error_deg",
]
