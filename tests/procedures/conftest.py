"""One run per scenario (its fast variant) for the procedure tests of a module, typed as the runner returns it."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from headsim.run.result import RunResult
from headsim.run.runner import run_scenario
from headsim.scenario.loading import load_scenario


@pytest.fixture(scope="module")
def fast_run() -> Callable[[str], RunResult]:
    """Run a scenario's fast variant once per test module; later calls return the same result."""
    runs: dict[str, RunResult] = {}

    def run(name: str) -> RunResult:
        if name not in runs:
            runs[name] = run_scenario(load_scenario(name, fast=True))
        return runs[name]

    return run
