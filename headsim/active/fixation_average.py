"""Averaging a converged fixation over images spread across one pixel.

A blob's detected column carries a sub-pixel rendering floor that depends on
the pixel's phase and not on the frame: repeated images at one pose repeat it.
One image's crossing (the fractional encoder step where the column would meet
its goal, from the learnt gain) is therefore off by that floor over the gain,
in encoder steps, which is more angle at a shorter focal length.  Images at
the whole steps that spread the target over one pixel of image motion sample
every phase; the mean of their crossings averages the floor out.  The head
decides how many from what it has learnt: the columns' scatter about the
crossing line (px) and the gain (px per step), against a target standard
error in encoder steps, the same angle at every zoom.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

#: Weight, in residuals, of the prior scatter in the learnt one.
PRIOR_RESIDUALS = 4


def pixel_period_steps(centre_steps: float, gain_px_per_step: float, most: int) -> list[int]:
    """Whole steps whose images spread evenly over one pixel of image motion around
    ``centre_steps``: consecutive steps, round(1 / |gain|) of them (one pixel's worth),
    every k-th step where that is more than ``most`` (at most ``most`` of them)."""
    per_pixel = max(1, round(1.0 / abs(gain_px_per_step)))
    stride = math.ceil(per_pixel / most)
    count = max(2, round(1.0 / (stride * abs(gain_px_per_step))))
    first = round(centre_steps - stride * (count - 1) / 2)
    return [first + stride * k for k in range(count)]


def samples_wanted(sigma_px: float, gain_px_per_step: float, target_steps: float) -> int:
    """Images whose mean crossing has a standard error of ``target_steps`` when one
    image's is ``sigma_px / |gain|`` steps (1: one image is enough)."""
    if target_steps <= 0 or gain_px_per_step == 0:
        return 1
    return max(1, math.ceil((sigma_px / (abs(gain_px_per_step) * target_steps)) ** 2 - 1e-9))


def detector_kind(detector: object) -> object:
    """What a detector finds, as a key: a ``functools.partial``'s function and arguments
    (two targets found the same way, say markers of one colour, share their images'
    scatter), else the detector itself."""
    if isinstance(detector, functools.partial):
        try:
            key = (
                detector_kind(detector.func),
                detector.args,
                tuple(sorted(detector.keywords.items())),
            )
            hash(key)
        except TypeError:
            return detector
        return key
    return detector


@dataclass
class ScatterMemory:
    """The detected columns' scatter about their crossing line, learnt per key
    (camera and kind of detector), px; it starts from ``prior_px``."""

    prior_px: float
    _sums: dict[object, tuple[float, int]] = field(default_factory=dict)

    def sigma_px(self, key: object) -> float:
        squares, count = self._sums.get(key, (self.prior_px**2 * PRIOR_RESIDUALS, PRIOR_RESIDUALS))
        return math.sqrt(squares / count)

    def add(self, key: object, residuals_px: np.ndarray, dof: int) -> None:
        """Pool ``residuals_px`` (about a mean fitted with ``len - dof`` freedoms lost)."""
        prior = (self.prior_px**2 * PRIOR_RESIDUALS, PRIOR_RESIDUALS)
        squares, count = self._sums.get(key, prior)
        self._sums[key] = (squares + float(residuals_px @ residuals_px), count + dof)


__all__ = [
    "PRIOR_RESIDUALS",
    "ScatterMemory",
    "detector_kind",
    "pixel_period_steps",
    "samples_wanted",
]
