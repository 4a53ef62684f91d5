"""Shared set-up for the live tests: a small head and the red marker's detector."""

from __future__ import annotations

from headsim.sim.settings import IDEAL_FOCAL_PX, CameraSettings, HeadSettings
from headsim.vision.markers import MarkerDetector

RED = MarkerDetector("red")


def small_head(scale: float = 0.5) -> HeadSettings:
    focal = IDEAL_FOCAL_PX * scale
    cam = CameraSettings(width=int(640 * scale), height=int(480 * scale), kx=focal, ky=focal)
    return HeadSettings(cameras=(cam, cam))
