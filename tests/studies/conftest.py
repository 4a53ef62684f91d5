"""Fixtures shared by the study's tests: one calibration of every method per session."""

from __future__ import annotations

import pytest

from headsim.sim.settings import paper_head
from headsim.studies.calibrations import Calibrations, calibrate_methods
from headsim.studies.methods import StudyConfig


@pytest.fixture(scope="session")
def calibrations() -> Calibrations:
    """Every method calibrated once on the paper's head, small (about 5 s)."""
    config = StudyConfig.quick()
    return calibrate_methods(paper_head(seed=config.seed), config)
