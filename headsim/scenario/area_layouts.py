"""Object layouts that populate chosen areas S1..S12 of Sec. III (placement, truth allowed).

Random layouts rarely reach the areas split by the magnitude test (S1-S4,
S7, S8): they lie in thin wedges around the lines of sight.  Here objects are
drawn by rejection from the true geometry (``areas_from_geometry`` at the
reference's true fixation angles) and kept only where all four images (each
camera at each fixation) see them whole.  This is placement, like putting an
object on a bench: the measurement still uses images alone.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from headsim.estimators.areas import areas_from_geometry
from headsim.geometry.sampling import sample_points_head
from headsim.geometry.stereo_view import StereoView
from headsim.scenario.scene import start_head_to_world
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import effective_initial_direction, start_views


def reference_angles(settings: HeadSettings, reference_head: np.ndarray) -> tuple[float, float]:
    """True encoder angles (alpha1, alpha2) at which Ca1, Ca2 fixate a point in H, rad."""
    half = settings.baseline_m / 2
    x, _, z = reference_head
    alpha1 = math.atan2(x + half, z) - effective_initial_direction(settings, 0)
    alpha2 = math.atan2(half - x, z) - effective_initial_direction(settings, 1)
    return alpha1, alpha2


def seen_in_four_images(
    views: Sequence[StereoView], points_world: np.ndarray, radius_m: float
) -> np.ndarray:
    """(N,) whether both cameras see each point whole in every one of ``views`` (no render)."""
    ok = np.ones(len(points_world), dtype=bool)
    for view in views:
        ok &= view.sees_whole(points_world, radius_m)
    return ok


def _hides_or_hidden(
    points_head: np.ndarray, reference_head: np.ndarray, baseline_m: float, clear_m: float
) -> np.ndarray:
    """(N,) whether a point's ray from a camera centre passes within ``clear_m`` of the reference."""
    close = np.zeros(len(points_head), dtype=bool)
    for sign in (-1.0, 1.0):
        centre = np.array([sign * baseline_m / 2, 0.0, 0.0])
        to_ref = reference_head - centre
        to_p = points_head - centre
        cos = to_p @ to_ref / (np.linalg.norm(to_p, axis=1) * np.linalg.norm(to_ref))
        angle = np.arccos(np.clip(cos, -1.0, 1.0))
        close |= angle < clear_m / np.linalg.norm(to_ref)
    return close


def _overlaps(
    points_head: np.ndarray,
    placed_head: Sequence[np.ndarray],
    baseline_m: float,
    radius_m: float,
    gap_rad: float,
) -> np.ndarray:
    """(N,) whether a point's image would touch an already placed object's, in either camera.

    Seen from either camera centre, two balls of ``radius_m`` are apart when
    the angle between their rays exceeds the sum of their angular radii plus
    ``gap_rad``.  The eyes only yaw about their centres, so this holds at
    every eye angle: one partly hiding the other would bias both centroids.
    """
    close = np.zeros(len(points_head), dtype=bool)
    for other in placed_head:
        for sign in (-1.0, 1.0):
            centre = np.array([sign * baseline_m / 2, 0.0, 0.0])
            to_o, to_p = other - centre, points_head - centre
            d_o, d_p = np.linalg.norm(to_o), np.linalg.norm(to_p, axis=1)
            angle = np.arccos(np.clip(to_p @ to_o / (d_p * d_o), -1.0, 1.0))
            close |= angle < radius_m / d_o + radius_m / d_p + gap_rad
    return close


def area_layout(
    settings: HeadSettings,
    reference_head: np.ndarray,
    wanted: Sequence[int],
    rng: np.random.Generator,
    *,
    depth_m: tuple[float, float] = (0.3, 2.5),
    lateral: float = 0.4,
    vertical: tuple[float, float] = (-0.12, 0.08),
    radius_m: float = 0.004,
    clear_m: float = 0.085,
    batches: int = 40,
    partial: bool = False,
    gap_rad: float = 0.01,
    scene: str = "blocks",
) -> np.ndarray:
    """Positions in H (len(wanted), 3), m: object k in true area ``wanted[k]``, seen in all four images.

    Draws batches of 4000 candidates (depth, then |x/z| <= ``lateral``, y/z in
    ``vertical``), at most ``batches`` of them; ValueError names the areas
    it could not fill (with ``partial``, their rows are NaN instead).  No object is placed where it would hide the reference
    or be hidden by it: seen from either camera, its ray is ``clear_m`` (at
    the reference's distance) or more from the reference's.  Nor where its
    image would touch another placed object's (``gap_rad`` between the balls'
    edges, seen from either camera): a partly hidden ball's centroid moves by
    up to its radius, which the images cannot tell from a shift.  The head
    ``settings`` at its start pose in ``scene`` (the neck at 0), the eyes
    turned to the reference's fixations.
    """
    alpha1, alpha2 = reference_angles(settings, reference_head)
    effective = (effective_initial_direction(settings, 0), effective_initial_direction(settings, 1))
    views = start_views(settings, scene, (alpha1, alpha2))[1:]
    chosen: list[np.ndarray | None] = [None] * len(wanted)
    for _ in range(batches):
        n = 4000
        points = sample_points_head(rng, n, (-lateral, lateral), vertical, depth_range_m=depth_m)
        areas = areas_from_geometry(points, alpha1, alpha2, settings.baseline_m, effective)
        areas[_hides_or_hidden(points, reference_head, settings.baseline_m, clear_m)] = 0
        world = start_head_to_world(settings, points)
        for k, area in enumerate(wanted):
            if chosen[k] is not None:
                continue
            candidates = np.flatnonzero(areas == area)
            placed = [c for c in chosen if c is not None]
            if placed and candidates.size:
                apart = ~_overlaps(
                    points[candidates], placed, settings.baseline_m, radius_m, gap_rad
                )
                candidates = candidates[apart]
            candidates = candidates[:50]
            if candidates.size == 0:
                continue
            seen = seen_in_four_images(views, world[candidates], radius_m)
            if seen.any():
                pick = int(candidates[np.flatnonzero(seen)[0]])
                chosen[k] = points[pick]
                areas[pick] = 0  # not twice
        if all(c is not None for c in chosen):
            return np.array(chosen)
    if partial:
        return np.array([np.full(3, np.nan) if c is None else c for c in chosen])
    missing = sorted({wanted[k] for k, c in enumerate(chosen) if c is None})
    raise ValueError(
        f"area layout: no position seen in all four images found for areas {missing} "
        f"in {batches} batches"
    )


__all__ = ["area_layout", "reference_angles", "seen_in_four_images"]
