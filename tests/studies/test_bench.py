"""The regression bench: its comparison rules, and that it catches injected regressions.

The whole suite is `make regress` (CI runs it after the tests): here the bench's machinery
runs on its smallest part (ideal cameras, Model 2) and on the part a fault needs.
"""

from __future__ import annotations

import pytest

from headsim.studies.bench import PARTS, Faults, suite
from headsim.studies.checks import BASELINE, TOLERANCES, compare, format_table, load_json

#: The metrics of the ideal part (``headsim.studies.bench._ideal_part``).
IDEAL_PREFIXES = ("ideal.", "windows.", "speed.wall_per_point_over_render")


@pytest.fixture(scope="module")
def stored() -> tuple[dict, dict]:
    return load_json(BASELINE)["metrics"], load_json(TOLERANCES)


@pytest.fixture(scope="module")
def clean() -> dict[str, float]:
    """The ideal part on this code, once: the pass test and the fault test's clean half."""
    return suite(seed=load_json(BASELINE)["seed"], parts=("ideal",))


def test_a_part_gives_its_baseline_metrics_and_passes_on_this_code(stored, clean) -> None:
    baseline, tolerances = stored
    assert "ideal" in PARTS
    assert set(clean) == {m for m in baseline if m.startswith(IDEAL_PREFIXES)}
    assert all(m in tolerances for m in clean)
    verdicts = compare(clean, baseline, tolerances)
    # Speed ratios (25 % tolerance) are for `headsim bench` on a quiet machine, not for
    # a unit test that shares the machine with others.
    assert not [v for v in verdicts if v.regressed and not v.metric.startswith("speed.")], (
        format_table(verdicts)
    )


def test_an_injected_regression_is_caught_and_the_clean_run_passes(stored, clean) -> None:
    baseline, tolerances = stored
    caught = "ideal.model2.renders_per_point"
    seed = load_json(BASELINE)["seed"]
    metrics = suite(seed=seed, faults=Faults(double_renders=True), parts=("ideal",))
    verdicts = {v.metric: v for v in compare(metrics, baseline, tolerances)}
    assert verdicts[caught].regressed
    # The same part without the fault passes: the fault, not noise, is caught.
    passed = {v.metric: v for v in compare(clean, baseline, tolerances)}
    assert not passed[caught].regressed


def test_a_wrong_mount_sign_is_caught_by_the_paper_part(stored) -> None:
    """The paper part with the fault (its clean run is `make regress`'s)."""
    baseline, tolerances = stored
    seed = load_json(BASELINE)["seed"]
    metrics = suite(seed=seed, faults=Faults(mount_sign=True), parts=("paper",))
    verdicts = {v.metric: v for v in compare(metrics, baseline, tolerances)}
    assert verdicts["paper.model2.z_rms_pct_depth"].regressed
