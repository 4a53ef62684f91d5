"""Shared fixtures: real MuJoCo models, real off-screen rendering."""

from __future__ import annotations

import signal

import numpy as np
import pytest

import headsim  # noqa: F401  (sets MUJOCO_GL before mujoco is imported)

# The suite tests Ctrl-C. A suite started as a background job (`pytest &` in a script)
# inherits SIGINT ignored, and so would every command it starts: undo that here, so
# the interrupt tests test headsim and not how pytest was launched.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
