"""Where the calibration targets are placed: seeded positions that both cameras
see whole.  Placement only: it uses the truth (the true intrinsics), never the
measurement path.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from headsim.geometry.sampling import sample_points_head
from headsim.sim import names
from headsim.sim.simulator import HeadSim


def calibration_layout(
    sim: HeadSim,
    rng: np.random.Generator,
    count: int = 60,
    depth_range_m: tuple[float, float] = (0.25, 0.6),
    lateral: float = 0.16,
    vertical: float = 0.08,
    radius_m: float = 0.008,
    depths_m: np.ndarray | None = None,
    eye_angles_rad: Sequence[float] = (),
) -> np.ndarray:
    """World positions (count, 3) for Sec. V calibration targets, seeded.

    Near targets spread sideways separate the two offsets best (eq. 23 is one
    equation in two unknowns per sample; their sec^2 terms differ most up
    close): 60 targets at 0.25-0.6 m recover them to about 1e-4 rad with the
    paper's cameras.  ``lateral``/``vertical``: x_h/z_h and y_h/z_h spread; a
    vertical spread is what the extended calibration needs.  Every position is
    seen whole (ball of ``radius_m``) by both cameras at the current pose, or
    at one of ``eye_angles_rad`` (encoder angles, neck still): at a long focal
    length the near, lateral positions that separate the offsets are in the
    common view only with the eyes turned in (Model 2 finds them by search;
    the first position is always in view at the current pose).
    ``depths_m``: (count,) each position's depth z_h, m, kept when it is drawn
    again (e.g. :func:`headsim.scenario.calibration_design.near_far_depths`); None:
    uniform in ``depth_range_m``.
    """
    resolution = sim.settings.encoder_resolution_rad
    eye_steps = [round(a / resolution) for a in eye_angles_rad]

    def seen(points: np.ndarray) -> np.ndarray:
        ok = seen_by_both(sim, points, radius_m)
        if eye_steps:
            before = sim.eye_encoder_steps()
            for steps in eye_steps:
                sim.command_eye_steps(steps)
                sim.settle()
                ok |= seen_by_both(sim, points, radius_m)
            sim.command_eye_steps(before)
            sim.settle()
        return ok

    def draw(n: int, slots: np.ndarray | None = None) -> np.ndarray:
        return sample_points_head(
            rng,
            n,
            (-lateral, lateral),
            (-vertical, vertical),
            depth_range_m=depth_range_m if depths_m is None else None,
            depths_m=None if depths_m is None else depths_m[slots],
        )

    if depths_m is not None:
        depths_m = np.asarray(depths_m, dtype=float)
        if depths_m.shape != (count,):
            raise ValueError(f"depths_m must have shape ({count},), got {depths_m.shape}")
    points_world = sim.transform_points(draw(count, np.arange(count)), "head", "world")
    # Placement (truth allowed): keep positions both cameras see whole from where the
    # head stands; a position that one cannot see is drawn again, a bounded number of times.
    for _ in range(500):
        unseen = ~seen(points_world)
        # The first position in view from where the head stands: the servo learns
        # its gains there, which the search for the others needs.
        unseen[0] |= not seen_by_both(sim, points_world[:1], radius_m)[0]
        if not unseen.any():
            return points_world
        points_world[unseen] = sim.transform_points(
            draw(int(unseen.sum()), np.flatnonzero(unseen)), "head", "world"
        )
    raise ValueError(
        f"calibration layout: {int(unseen.sum())} of {count} positions stay outside a camera's "
        f"view after 500 draws: depth {depth_range_m} m, lateral {lateral}, vertical {vertical} "
        "reach outside the field both cameras share at this focal length"
    )


def seen_by_both(sim: HeadSim, points_world: np.ndarray, radius_m: float = 0.0) -> np.ndarray:
    """(N,) whether each world point images whole inside both cameras at the current pose.

    Placement and checks only (it uses the true intrinsics): the point's image,
    plus its apparent radius and 2 px, lies inside the image.
    """
    points_world = np.atleast_2d(points_world)
    ok = np.ones(len(points_world), dtype=bool)
    for camera in (1, 2):
        cam = sim.camera_settings(camera)
        uv = sim.project(points_world, camera)
        depth = sim.transform_points(points_world, "world", names.CAMERAS[camera - 1])[:, 2]
        margin = 2.0 + max(cam.kx, cam.ky) * radius_m / np.maximum(depth, 1e-9)
        with np.errstate(invalid="ignore"):
            ok &= (
                (depth > 0)
                & (uv[:, 0] >= margin)
                & (uv[:, 0] <= cam.width - 1 - margin)
                & (uv[:, 1] >= margin)
                & (uv[:, 1] <= cam.height - 1 - margin)
            )
    return ok


__all__ = ["calibration_layout", "seen_by_both"]
