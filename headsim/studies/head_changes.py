"""Heads the study measures on: the cameras changed after calibration (zoom, principal
point, k1, noise, encoder), registered by name as the hooks the study's experiment file
(``study_experiments.toml``) names, and each eye's true image-centre direction, rad."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

from headsim.active.principal import zoomed
from headsim.sim.settings import HeadSettings
from headsim.studies.hooks import registrar

#: A change of the head to one value of an experiment.
HeadChange = Callable[[HeadSettings, float], HeadSettings]
#: The hooks an experiment file names: name -> change.
HEAD_CHANGES: dict[str, HeadChange] = {}
#: ``@head_change("name")``: register a change under the name experiment files use.
head_change = registrar(HEAD_CHANGES)


head_change("zoom")(zoomed)


@head_change("none")
def unchanged(settings: HeadSettings, _value: float) -> HeadSettings:
    """The head as it is (a sweep of the targets, not the head)."""
    return settings


def centred(settings: HeadSettings) -> HeadSettings:
    """The same head with both principal points at the image centre."""
    cam1, cam2 = (replace(c, cx=None, cy=None) for c in settings.cameras)
    return replace(settings, cameras=(cam1, cam2))


@head_change("principal_shift_px")
def principal_shifted(settings: HeadSettings, shift_px: float) -> HeadSettings:
    """Principal points moved ``shift_px``: Ca1's u by +shift, Ca2's u by -shift, both v by +shift.

    Mirror images in u, so that the image centre's rays of both eyes turn
    the same way relative to their inward directions and their effect on
    the depth adds up instead of cancelling.
    """
    cams = []
    for sign, cam in zip((1.0, -1.0), settings.cameras, strict=True):
        cx, cy = cam.principal
        cams.append(replace(cam, cx=cx + sign * shift_px, cy=cy + shift_px))
    return replace(settings, cameras=(cams[0], cams[1]))


@head_change("k1_change")
def k1_changed(settings: HeadSettings, change: float) -> HeadSettings:
    """Both cameras' k1 changed by ``change`` (positive: less barrel distortion)."""
    cam1, cam2 = (replace(c, k1=c.k1 + change) for c in settings.cameras)
    return replace(settings, cameras=(cam1, cam2))


@head_change("noise_std")
def with_noise(settings: HeadSettings, noise_std: float) -> HeadSettings:
    """Both cameras with Gaussian image noise of ``noise_std`` grey levels."""
    cam1, cam2 = (replace(c, noise_std=noise_std) for c in settings.cameras)
    return replace(settings, cameras=(cam1, cam2))


@head_change("encoder_steps_per_turn")
def with_encoder(settings: HeadSettings, steps_per_turn: float) -> HeadSettings:
    """The eye encoder with ``steps_per_turn`` steps per revolution."""
    return replace(settings, encoder_resolution_rad=2 * math.pi / steps_per_turn)
