"""Shared fixture: one Zhang calibration per preset for every stereo test (real renders)."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.head.sim_head import SimHead
from headsim.sim.simulator import HeadSim
from headsim.stereo.calibration import (
    StereoCalibration,
    calibrate_stereo,
)
from headsim.stereo.views import ChessboardViews, chessboard_views

from .helpers import PRESETS, TEST_POSES


@pytest.fixture(scope="package", params=sorted(PRESETS))
def calibrated(request) -> tuple[str, ChessboardViews, StereoCalibration]:
    with HeadSim("chessboard", PRESETS[request.param]()) as sim:
        head = SimHead(sim)
        views = chessboard_views(head, TEST_POSES, np.random.default_rng(3))
        calib = calibrate_stereo(head, views)
    return request.param, views, calib
