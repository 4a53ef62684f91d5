"""OpenCV's pool held to the calling thread, and given back."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from headsim.lockstep.detect import find_markers_stacked
from headsim.vision.threads import serial_opencv


@pytest.fixture
def two_threads():
    before = cv2.getNumThreads()
    cv2.setNumThreads(2)
    yield
    cv2.setNumThreads(before)


@pytest.mark.fast
def test_the_block_runs_serially_and_gives_the_setting_back(two_threads) -> None:
    with serial_opencv():
        assert cv2.getNumThreads() == 1
    assert cv2.getNumThreads() == 2
    with pytest.raises(RuntimeError), serial_opencv():
        raise RuntimeError("a detection failed")
    assert cv2.getNumThreads() == 2


@pytest.mark.fast
def test_a_stacked_detection_leaves_the_process_s_setting(two_threads) -> None:
    images = np.zeros((3, 40, 50, 3), np.uint8)
    images[1, 10:16, 20:27, 0] = 255  # a red blob in the second image only
    found = find_markers_stacked(images, "red")
    assert [d.found for d in found] == [False, True, False]
    assert cv2.getNumThreads() == 2
