"""Target positions for the orchestrators, in the head frame H, m: the Tables V/VI targets,
the seeded samplers (both draw with :func:`headsim.geometry.sampling.sample_points_head`),
and placing a body at a point given in H."""

from __future__ import annotations

import math

import numpy as np

from headsim.geometry.sampling import sample_points_head
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim

#: The six target positions of the Tables V/VI comparison, in H, m: 0.4-1.2 m
#: deep, spread sideways and vertically around x_h/z_h = 0.05, where the paper
#: preset's eyes (both turned towards +x by their mounts) share their views:
#: all are seen by both cameras at eye angle 0 and in the active method's step
#: images, also after a 1.5x or 0.7x zoom.
TABLE_TARGETS_HEAD = (
    (0.030, 0.010, 0.40),
    (0.005, 0.025, 0.55),
    (0.075, -0.035, 0.70),
    (0.000, -0.030, 0.85),
    (0.095, 0.045, 1.00),
    (0.010, 0.030, 1.20),
)


def place_in_head(sim: HeadSim, body: str, p_head: np.ndarray) -> None:
    """Move ``body`` to ``p_head`` (3,), a point in the head frame H, m."""
    sim.set_body_pose(body, sim.truth.transform_points(p_head, "head", "world")[0])


def table_targets(count: int = len(TABLE_TARGETS_HEAD)) -> np.ndarray:
    """The first ``count`` of :data:`TABLE_TARGETS_HEAD` (count, 3), m."""
    return np.array(TABLE_TARGETS_HEAD[:count], dtype=float)


def depth_targets(
    settings: HeadSettings,
    depth_m: float,
    count: int,
    rng: np.random.Generator,
    lateral: float = 0.06,
    vertical: float = 0.05,
) -> np.ndarray:
    """``count`` targets (count, 3) in H at depth ``depth_m``, m.

    x/z is uniform within ``lateral`` of the direction both eyes look along
    at eye angle 0 (the mean of their mount yaws, read from the settings to
    place targets only), y/z within ``vertical`` of 0.
    """
    look = math.tan((settings.cameras[0].mount_yaw_rad - settings.cameras[1].mount_yaw_rad) / 2)
    return sample_points_head(
        rng,
        count,
        (-lateral, lateral),
        (-vertical, vertical),
        depths_m=np.full(count, depth_m),
        lateral_centre=look,
    )


def random_targets_head(
    rng: np.random.Generator,
    count: int,
    depth_range_m: tuple[float, float],
    lateral: float = 0.12,
    vertical: tuple[float, float] = (-0.25, 0.25),
) -> np.ndarray:
    """Points (count, 3) in H: depth uniform in the range, x/z and y/z uniform."""
    return sample_points_head(
        rng, count, (-lateral, lateral), vertical, depth_range_m=depth_range_m
    )


def visible_vertical_range(settings: HeadSettings, margin: float = 0.85) -> tuple[float, float]:
    """y/z range both cameras see (with a margin), from their true intrinsics.

    For placing test targets only; the method itself never reads intrinsics.
    """
    up = min(c.principal[1] / c.ky for c in settings.cameras)
    down = min((c.height - 1 - c.principal[1]) / c.ky for c in settings.cameras)
    return (-margin * up, margin * down)
