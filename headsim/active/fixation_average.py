"""Averaging a converged fixation over images spread across one pixel.

A blob's detected column carries a sub-pixel rendering floor that depends on
the pixel's phase and not on the frame: repeated images at one pose repeat it.
One image's crossing (the fractional encoder step where the column would meet
its goal, from the learnt gain) is therefore off by that floor over the gain,
in encoder steps, which is more angle at a shorter focal length.  Images at
the whole steps that spread the target over one pixel of image motion (the
floor's period) sample every phase; the mean of their crossings averages the
floor out, at every zoom alike.
"""

from __future__ import annotations

import math


def pixel_period_steps(centre_steps: float, gain_px_per_step: float, most: int) -> list[int]:
    """Whole steps whose images spread evenly over one pixel of image motion around
    ``centre_steps``: consecutive steps, round(1 / |gain|) of them (one pixel's worth),
    every k-th step where that is more than ``most`` (at most ``most`` of them)."""
    per_pixel = max(1, round(1.0 / abs(gain_px_per_step)))
    stride = math.ceil(per_pixel / most)
    count = max(2, round(1.0 / (stride * abs(gain_px_per_step))))
    first = round(centre_steps - stride * (count - 1) / 2)
    return [first + stride * k for k in range(count)]


__all__ = ["pixel_period_steps"]
