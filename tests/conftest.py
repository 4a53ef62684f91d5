"""Shared fixtures: real MuJoCo models, real off-screen rendering; the suite's tiers.

Every test falls in exactly one tier, a marker (``pytest -m fast``, ``make test-fast``):

- ``fast``: pure math, estimators, scenario checks; no render (a fast test that creates
  a renderer fails: :func:`_no_render_in_the_fast_tier`);
- ``render``: components with real MuJoCo renders (the simulator, servos, vision, ...);
- ``e2e``: the whole program: the command line, procedures, studies, docs examples.

A test's own ``@pytest.mark.fast``/``render``/``e2e`` (or its module's ``pytestmark``)
decides; otherwise its directory or file does (:data:`TIER_OF_PATH`), and anything not
listed there is ``render``.
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from shipped_runs import ShippedRun, run_shipped

import headsim.cli  # headsim sets MUJOCO_GL before anything imports mujoco

# The suite tests Ctrl-C. A suite started as a background job (`pytest &` in a script)
# inherits SIGINT ignored, and so would every command it starts: undo that here, so
# the interrupt tests test headsim and not how pytest was launched.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
# Ctrl-C during the suite stops the suite: a test that drives the CLI in-process (main(argv))
# gets KeyboardInterrupt back instead of exit code 130 and a suite that runs on.
headsim.cli.RAISE_INTERRUPTS = True

TESTS = Path(__file__).resolve().parent
TIERS = ("fast", "render", "e2e")
#: The tier of the tests under a directory or in a file of tests/ (the first part of its
#: path); the rest are ``render``.
TIER_OF_PATH = {
    "geometry": "fast",
    "estimators": "fast",
    "scenario": "fast",
    "stereo": "fast",
    "test_errors.py": "fast",
    "test_files.py": "fast",
    "test_import_graph.py": "fast",
    "test_paper.py": "fast",
    "test_self_contained.py": "fast",
    "cli": "e2e",
    "procedures": "e2e",
    "studies": "e2e",
    "test_docs_examples.py": "e2e",
    "test_install.py": "e2e",
    "test_readme_figures.py": "e2e",
}


def tier_of(item: pytest.Item) -> str:
    """The tier of ``item``: its own marker, else its path's (:data:`TIER_OF_PATH`)."""
    own = [name for name in TIERS if item.get_closest_marker(name) is not None]
    if len(own) > 1:
        raise pytest.UsageError(f"{item.nodeid}: in more than one tier ({', '.join(own)})")
    if own:
        return own[0]
    path = Path(str(item.path)).resolve()
    if not path.is_relative_to(TESTS):
        return "render"
    return TIER_OF_PATH.get(path.relative_to(TESTS).parts[0], "render")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        tier = tier_of(item)
        if item.get_closest_marker(tier) is None:
            item.add_marker(getattr(pytest.mark, tier))


@pytest.fixture(autouse=True)
def _no_render_in_the_fast_tier(request: pytest.FixtureRequest) -> Iterator[None]:
    """A ``fast`` test that creates a renderer (an OpenGL context) fails: mark it ``render``."""
    if request.node.get_closest_marker("fast") is None:
        yield
        return
    import mujoco

    from headsim.sim import render

    def refuse(*args: object, **kwargs: object) -> None:
        pytest.fail(
            f"{request.node.nodeid} renders but is in the fast tier: mark it "
            "@pytest.mark.render (or move it)",
            pytrace=False,
        )

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(mujoco, "Renderer", refuse)
        patch.setattr(mujoco, "GLContext", refuse)
        patch.setattr(render, "_acquire", refuse)
        yield


@pytest.fixture(scope="session")
def shipped_fast_run(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], ShippedRun]:
    """Run a shipped scenario's fast variant through the command line once per session; later
    calls return the same run.  The runner's tests check the command's files and output,
    the procedures' tests the typed result: one run serves both."""
    runs: dict[str, ShippedRun] = {}

    def run(name: str) -> ShippedRun:
        if name not in runs:
            runs[name] = run_shipped(name, tmp_path_factory.mktemp(name))
        return runs[name]

    return run


@pytest.fixture
def did_not_run(request: pytest.FixtureRequest) -> Callable[[str], None]:
    """Say that a path cannot run here (a GPU, a driver, an extra not installed): the
    sentences are listed at the end of the run, also when workers run the tests."""

    def say(sentence: str) -> None:
        request.node.user_properties.append(("did_not_run", sentence))

    return say


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """List every path that said it did not run (:func:`did_not_run`)."""
    said = {
        value
        for reports in terminalreporter.stats.values()
        for report in reports
        for key, value in getattr(report, "user_properties", ())
        if key == "did_not_run"
    }
    if said:
        terminalreporter.section("did not run here")
        for sentence in sorted(said):
            terminalreporter.line(sentence)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
