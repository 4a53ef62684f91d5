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
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from headsim.active.servo_types import Detector, ServoResult
from headsim.active.windows import windowed

if TYPE_CHECKING:
    from headsim.active.eye_servo import EyeServo


def pixel_period_steps(centre_steps: float, gain_px_per_step: float, most: int) -> list[int]:
    """Whole steps whose images spread evenly over one pixel of image motion around
    ``centre_steps``: consecutive steps, round(1 / |gain|) of them (one pixel's worth),
    every k-th step where that is more than ``most`` (at most ``most`` of them)."""
    per_pixel = max(1, round(1.0 / abs(gain_px_per_step)))
    stride = math.ceil(per_pixel / most)
    count = max(2, round(1.0 / (stride * abs(gain_px_per_step))))
    first = round(centre_steps - stride * (count - 1) / 2)
    return [first + stride * k for k in range(count)]


def average_eye_crossing(
    servo: EyeServo, camera: int, detector: Detector, goal: float, result: ServoResult
) -> ServoResult:
    """The eye servo's converged ``result`` with its crossing averaged over images spread
    across one pixel around it (see ``ServoConfig.average_fixation``); the eye ends at
    ``result.steps``."""
    cfg, sim = servo.config, servo.sim
    gain = result.gain_px_per_step
    if not cfg.average_fixation or not gain or result.uv is None or not windowed(detector):
        return result
    low, high = servo.step_range
    poses = [
        s
        for s in pixel_period_steps(result.subpixel_steps, gain, cfg.max_fixation_samples)
        if low <= s <= high
    ]
    seen = {s: u for s, u, _ in result.seen}
    path = list(result.seen)
    samples: list[tuple[int, float]] = []
    renders = 0
    for s in poses:  # bounded: at most max_fixation_samples poses
        if s not in seen:
            sim.command_eye_steps(s)
            sim.settle()
            detection = servo.observe(camera, detector)
            renders += 1
            if not detection.found or detection.uv is None:
                break  # the averaging is bounded by what the images show
            seen[s] = detection.uv[0]
            path.append((s, *detection.uv))
        samples.append((s, seen[s]))
    if sim.eye_encoder_steps() != result.steps:
        sim.command_eye_steps(result.steps)
        sim.settle()
    if len(samples) < 2:
        return replace(result, renders=result.renders + renders, seen=tuple(path))
    crossings = np.array([s - (u - goal) / gain for s, u in samples])
    subpixel = float(crossings.mean())
    return replace(
        result,
        subpixel_steps=subpixel,
        renders=result.renders + renders,
        seen=tuple(path),
        fixation_samples=len(samples),
    )


__all__ = ["average_eye_crossing", "pixel_period_steps"]
