"""Random target positions in H: the one sampler every layout draws from.

Frames as in docs/equations.md: H has x right (C1 to C2), y down, z forward,
origin mid-baseline; positions in metres.  A point is drawn as its depth z_h,
then its horizontal slope x_h / z_h, then its vertical slope y_h / z_h, each
uniform, in that order of generator calls, so a seeded layout is the same
wherever it is drawn.
"""

from __future__ import annotations

import numpy as np

__all__ = ["sample_points_head"]


def sample_points_head(
    rng: np.random.Generator,
    count: int,
    lateral: tuple[float, float],
    vertical: tuple[float, float],
    *,
    depth_range_m: tuple[float, float] | None = None,
    depths_m: np.ndarray | None = None,
    lateral_centre: float | None = None,
) -> np.ndarray:
    """Points (count, 3) in H, m: z_h, then x_h / z_h in ``lateral``, then y_h / z_h in ``vertical``.

    The depth is drawn uniform in ``depth_range_m`` (m) unless ``depths_m``
    ((count,), m) gives it, in which case the generator draws no depths.
    ``lateral_centre``: a slope added to each drawn x_h / z_h before it is
    scaled by the depth (the direction the eyes look along); None adds nothing.
    """
    if depth_range_m is not None and depths_m is None:
        z = rng.uniform(*depth_range_m, size=count)
    elif depth_range_m is None and depths_m is not None:
        z = depths_m
    else:
        raise ValueError("give exactly one of depth_range_m and depths_m")
    slope_x = rng.uniform(*lateral, size=count)
    if lateral_centre is not None:
        slope_x = lateral_centre + slope_x
    return np.column_stack([slope_x * z, rng.uniform(*vertical, size=count) * z, z])
