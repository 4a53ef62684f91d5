"""Heads changed after calibration: each change moves what it says."""

from __future__ import annotations

import math

import pytest

from headsim.sim.settings import paper_head
from headsim.studies.head_changes import (
    centred,
    k1_changed,
    principal_shifted,
    with_encoder,
    with_noise,
)


def test_head_changes_move_what_they_say() -> None:
    head = paper_head()
    shifted = principal_shifted(head, 5.0)
    (cx1, cy1), (cx2, cy2) = (c.principal for c in head.cameras)
    assert shifted.cameras[0].principal == (cx1 + 5, cy1 + 5)
    assert shifted.cameras[1].principal == (cx2 - 5, cy2 + 5)
    assert [c.k1 for c in k1_changed(head, 0.1).cameras] == pytest.approx(
        [c.k1 + 0.1 for c in head.cameras]
    )
    assert with_encoder(head, 6400).encoder_resolution_rad == pytest.approx(2 * math.pi / 6400)
    assert all(c.noise_std == 4 for c in with_noise(head, 4).cameras)
    assert all(c.principal == c.image_centre for c in centred(head).cameras)
