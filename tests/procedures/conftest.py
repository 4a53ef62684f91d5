"""The procedure tests read the typed result of each scenario's fast variant, run once for the
whole suite (``shipped_fast_run`` in tests/conftest.py, shared with the runner's tests)."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from shipped_runs import ShippedRun

from headsim.runs.result import RunResult


@pytest.fixture
def fast_run(shipped_fast_run: Callable[[str], ShippedRun]) -> Callable[[str], RunResult]:
    """A shipped scenario's fast variant, as the runner returned it (one run per session)."""
    return lambda name: shipped_fast_run(name).result
