"""Markers found over a stack of images give find_marker's answers, image by image:
exact synthetic images (anti-aliased discs drawn with OpenCV), no render."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from headsim.lockstep import colour_weight_u8, find_markers_stacked
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import colour_weight, find_marker

pytestmark = pytest.mark.fast

SIZE = (96, 128)


def _disc(image: np.ndarray, centre: tuple[float, float], radius: float, rgb: tuple) -> None:
    """An anti-aliased disc at a sub-pixel centre (4 fractional bits)."""
    shift = 4
    c = (round(centre[0] * 2**shift), round(centre[1] * 2**shift))
    cv2.circle(image, c, round(radius * 2**shift), rgb, -1, cv2.LINE_AA, shift)


def _stack() -> np.ndarray:
    rng = np.random.default_rng(3)
    images = []
    for case in range(40):
        image = np.full((*SIZE, 3), 90, np.uint8)
        image += rng.integers(0, 6, image.shape, dtype=np.uint8)  # a grey, noisy background
        kind = case % 5
        if kind in (1, 2, 3, 4):  # one disc, somewhere inside
            centre = (rng.uniform(15, 113), rng.uniform(15, 81))
            _disc(image, centre, rng.uniform(1.5, 8.0), (230, 20, 25))
        if kind == 2:  # a second piece nearby: find_marker's own rules decide
            _disc(image, (centre[0] + 12, centre[1]), 3.0, (230, 20, 25))
        if kind == 3:  # cut by the border
            _disc(image, (1.0, 40.0), 5.0, (230, 20, 25))
        if kind == 4:  # half hidden behind a grey bar: the shape test says OCCLUDED
            image[:, int(centre[0]) :] = 90
        images.append(image)
    return np.stack(images)


def test_every_answer_is_find_markers() -> None:
    images = _stack()
    stacked = find_markers_stacked(images, "red")
    alone = [find_marker(image, "red") for image in images]
    assert stacked == alone
    statuses = {d.status for d in alone}
    assert statuses >= {
        DetectionStatus.LOST,
        DetectionStatus.FOUND,
        DetectionStatus.CUT,
        DetectionStatus.OCCLUDED,
    }


def test_the_weight_is_find_markers_weight() -> None:
    images = _stack()[:4]
    for colour in ("red", "green", "blue", "yellow"):
        weights = colour_weight_u8(images, colour)
        for image, weight in zip(images, weights, strict=True):
            np.testing.assert_allclose(weight / 255.0, colour_weight(image, colour), atol=1e-7)


def test_bad_input_names_what_is_allowed() -> None:
    with pytest.raises(ValueError, match=r"images must be \(m, H, W, 3\) uint8"):
        find_markers_stacked(np.zeros((96, 128, 3), np.uint8), "red")
    with pytest.raises(ValueError, match="unknown marker colour 'mauve'"):
        find_markers_stacked(np.zeros((1, 96, 128, 3), np.uint8), "mauve")
    assert find_markers_stacked(np.zeros((0, 96, 128, 3), np.uint8), "red") == []
