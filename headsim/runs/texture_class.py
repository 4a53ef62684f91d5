"""The texture class of a markerless target, from truth at placement (for the by-texture
table only; the head never learns it).

A target's class is the texture kind of the object it lies on (:data:`CLASS_OF_KIND`:
pink noise is ``rich``, a faint gradient ``low``, gratings and square stripes or checks
``repetitive``), unless part of the patch the correspondence compares is hidden from the
other eye at the start pose: then ``occluded``.  That patch is camera 1's template window
around the point (``MatchConfig().half_px``) and, the other way round, camera 2's window
around the point's projection there; each is sampled on a small grid of pixels whose
rays from the camera's true centre are cast into the scene, and a surface point so met
that the other camera's line of sight does not reach is hidden.
"""

from __future__ import annotations

import numpy as np

from headsim.runs.landing import ray_direction_world
from headsim.scenario.surface_targets import camera_centre, cast, visible
from headsim.sim.simulator import HeadSim
from headsim.sim.textured_scene import RoomSpec

#: The classes of the by-texture table, in the order it lists them.
TEXTURE_CLASSES = ("rich", "low", "repetitive", "occluded")
#: The class of each texture kind (:data:`headsim.sim.textures.TEXTURE_KINDS`).
CLASS_OF_KIND = {"pink": "rich", "low": "low", "grating": "repetitive", "repetitive": "repetitive"}
#: Pixels per side of the grid sampling a window (corners, edge midpoints, centre).
PATCH_GRID = 3


def texture_kinds(room: RoomSpec) -> dict[str, str]:
    """Each of the room's bodies (floor, walls, table, objects, clutter) and its texture kind."""
    return {obj.name: obj.texture.kind for obj in (*room.surfaces(), *room.objects)}


def patch_hidden(
    sim: HeadSim, point_world_m: np.ndarray, half_px: float, grid: int = PATCH_GRID
) -> bool:
    """Whether part of either camera's window (``half_px`` around the point's projection),
    sampled on ``grid`` x ``grid`` pixels, shows a surface point the other camera cannot see,
    at the simulator's pose now."""
    p = np.asarray(point_world_m, dtype=float)
    offsets = np.linspace(-half_px, half_px, grid)
    for seen, other in ((1, 2), (2, 1)):
        u, v = sim.truth.project(p[None, :], seen)[0]
        origin = camera_centre(sim, seen)
        for du in offsets:
            for dv in offsets:
                direction = ray_direction_world(sim, seen, (u + du, v + dv))
                hit, _, _ = cast(sim.model, sim.data, origin, direction)
                if hit is not None and not visible(sim, other, hit):
                    return True
    return False


def texture_class(
    sim: HeadSim, kinds: dict[str, str], body: str, point_world_m: np.ndarray, half_px: float
) -> str:
    """A target's class (:data:`TEXTURE_CLASSES`): ``occluded`` when :func:`patch_hidden`,
    else the class of the texture ``kinds`` gives ``body`` (``rich`` for a body it does not
    name: none of the shipped scenes' bodies is untextured in a room)."""
    if patch_hidden(sim, point_world_m, half_px):
        return "occluded"
    return CLASS_OF_KIND.get(kinds.get(body, "pink"), "rich")


__all__ = [
    "CLASS_OF_KIND",
    "PATCH_GRID",
    "TEXTURE_CLASSES",
    "patch_hidden",
    "texture_class",
    "texture_kinds",
]
