"""Where the calibration targets are placed: seeded positions that both cameras
see whole.  Placement only: it uses the truth (the true intrinsics), never the
measurement path.  Pure: the head's geometry comes in as views
(:meth:`headsim.sim.simulator.HeadSim.stereo_views`), taken once.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from headsim.geometry.sampling import sample_points_head
from headsim.geometry.stereo_view import StereoView
from headsim.geometry.transforms import apply_transform


def calibration_layout(
    views: Sequence[StereoView],
    rng: np.random.Generator,
    count: int = 60,
    depth_range_m: tuple[float, float] = (0.25, 0.6),
    lateral: float = 0.16,
    vertical: float = 0.08,
    radius_m: float = 0.008,
    depths_m: np.ndarray | None = None,
) -> np.ndarray:
    """World positions (count, 3) for Sec. V calibration targets, seeded.

    Near targets spread sideways separate the two offsets best (eq. 23 is one
    equation in two unknowns per sample; their sec^2 terms differ most up
    close): 60 targets at 0.25-0.6 m recover them to about 1e-4 rad with the
    paper's cameras.  ``lateral``/``vertical``: x_h/z_h and y_h/z_h spread; a
    vertical spread is what the extended calibration needs.  Every position is
    seen whole (ball of ``radius_m``) by both cameras in one of ``views``: the
    first is the head's current pose, the others the same head with the eyes
    turned (at a long focal length the near, lateral positions that separate
    the offsets are in the common view only with the eyes turned in; Model 2
    finds them by search; the first position is always in the first view).
    ``depths_m``: (count,) each position's depth z_h, m, kept when it is drawn
    again (e.g. :func:`headsim.scenario.calibration_design.near_far_depths`); None:
    uniform in ``depth_range_m``.
    """
    if not views:
        raise ValueError("calibration layout: views must hold at least the current pose")
    world_from_head = views[0].world_from_head

    def seen(points: np.ndarray) -> np.ndarray:
        ok = views[0].sees_whole(points, radius_m)
        for view in views[1:]:
            ok |= view.sees_whole(points, radius_m)
        return ok

    def draw(n: int, slots: np.ndarray | None = None) -> np.ndarray:
        points_head = sample_points_head(
            rng,
            n,
            (-lateral, lateral),
            (-vertical, vertical),
            depth_range_m=depth_range_m if depths_m is None else None,
            depths_m=None if depths_m is None else depths_m[slots],
        )
        return apply_transform(world_from_head, points_head)

    if depths_m is not None:
        depths_m = np.asarray(depths_m, dtype=float)
        if depths_m.shape != (count,):
            raise ValueError(f"depths_m must have shape ({count},), got {depths_m.shape}")
    points_world = draw(count, np.arange(count))
    # Placement (truth allowed): keep positions both cameras see whole from where the
    # head stands; a position that one cannot see is drawn again, a bounded number of times.
    for _ in range(500):
        unseen = ~seen(points_world)
        # The first position in view from where the head stands: the servo learns
        # its gains there, which the search for the others needs.
        unseen[0] |= not views[0].sees_whole(points_world[:1], radius_m)[0]
        if not unseen.any():
            return points_world
        points_world[unseen] = draw(int(unseen.sum()), np.flatnonzero(unseen))
    raise ValueError(
        f"calibration layout: {int(unseen.sum())} of {count} positions stay outside a camera's "
        f"view after 500 draws: depth {depth_range_m} m, lateral {lateral}, vertical {vertical} "
        "reach outside the field both cameras share at this focal length"
    )


__all__ = ["calibration_layout"]
