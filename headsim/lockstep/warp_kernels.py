"""Warp kernels of the lockstep device path (imported by :mod:`headsim.lockstep.warp_eyes`
only, once Warp is known to be installed and started)."""

from __future__ import annotations

import warp as wp


@wp.kernel
def marker_sums(
    packed: wp.array2d(dtype=wp.uint32),  # type: ignore[valid-type]
    rgb_adr: wp.array(dtype=int),  # type: ignore[valid-type]
    width: int,
    on: wp.vec3,
    threshold: float,
    sums: wp.array3d(dtype=wp.float64),  # type: ignore[valid-type]
) -> None:
    """One pixel of one camera of one world: its colour weight, min(on channels) -
    max(off channels) saturating at 0 (0..255), added to the image's (w, w u, w v) when
    above ``threshold``.  Pixels are Warp's packed words (B in the low byte, then G, R)."""
    world, camera, pixel = wp.tid()  # type: ignore[misc]
    value = packed[world, rgb_adr[camera] + pixel]
    b = float(value & wp.uint32(0xFF))
    g = float((value >> wp.uint32(8)) & wp.uint32(0xFF))
    r = float((value >> wp.uint32(16)) & wp.uint32(0xFF))
    low = 255.0
    high = 0.0
    if on[0] > 0.5:
        low = wp.min(low, r)
    else:
        high = wp.max(high, r)
    if on[1] > 0.5:
        low = wp.min(low, g)
    else:
        high = wp.max(high, g)
    if on[2] > 0.5:
        low = wp.min(low, b)
    else:
        high = wp.max(high, b)
    weight = wp.max(low - high, 0.0)
    if weight > threshold:
        w = wp.float64(weight / 255.0)
        u = wp.float64(pixel % width)
        v = wp.float64(pixel // width)
        wp.atomic_add(sums, world, camera, 0, w)
        wp.atomic_add(sums, world, camera, 1, w * u)
        wp.atomic_add(sums, world, camera, 2, w * v)
