"""Shared fixtures: real MuJoCo models, real off-screen rendering."""

from __future__ import annotations

import numpy as np
import pytest

import headsim  # noqa: F401  (sets MUJOCO_GL before mujoco is imported)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
