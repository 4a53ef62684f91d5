"""The status vocabulary and the image checks every detector shares."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.vision.detection import Detection, DetectionStatus, check_rgb, to_grey


def test_only_found_detections_are_found() -> None:
    assert Detection(DetectionStatus.FOUND, (1.0, 2.0), 3.0).found
    for status in (DetectionStatus.LOST, DetectionStatus.CUT, DetectionStatus.OCCLUDED):
        assert not Detection(status, None, 0.0).found


def test_grey_levels_of_rgb_and_single_channel_images() -> None:
    rgb = np.zeros((4, 6, 3), np.uint8)
    rgb[..., 0] = 255  # pure red: OpenCV's weights give 0.299 * 255
    assert to_grey(rgb).shape == (4, 6)
    assert int(to_grey(rgb)[0, 0]) == 76
    grey = np.arange(24, dtype=np.uint8).reshape(4, 6)
    assert to_grey(grey) is grey


@pytest.mark.parametrize(
    "image",
    [np.zeros((4, 6, 3), np.float32), np.zeros((4, 6, 4), np.uint8), np.zeros((4, 6), np.float64)],
)
def test_anything_but_rgb_uint8_is_refused_with_its_type_and_shape(image: np.ndarray) -> None:
    with pytest.raises(ValueError, match=r"expected an RGB uint8 image \(H, W, 3\), got "):
        check_rgb(image)
    with pytest.raises(ValueError, match=str(image.dtype)):
        to_grey(image)
