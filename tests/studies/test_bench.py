"""The regression bench: its comparison rules, and that it catches injected regressions."""

from __future__ import annotations

import pytest

from headsim.studies.bench import Faults, suite
from headsim.studies.bench_compare import BASELINE, TOLERANCES, compare, format_table, load_json


@pytest.fixture(scope="module")
def stored() -> tuple[dict, dict]:
    return load_json(BASELINE)["metrics"], load_json(TOLERANCES)


@pytest.fixture(scope="module")
def clean() -> dict[str, float]:
    """The whole suite on this code, once: the pass test and the fault tests' clean half."""
    return suite(seed=load_json(BASELINE)["seed"])


def test_the_suite_passes_on_this_code(stored, clean) -> None:
    baseline, tolerances = stored
    metrics = clean
    assert set(metrics) == set(baseline)
    verdicts = compare(metrics, baseline, tolerances)
    # Speed ratios (25 % tolerance) are for `headsim bench` on a quiet machine, not for
    # a unit test that shares the machine with others.
    assert not [v for v in verdicts if v.regressed and not v.metric.startswith("speed.")], (
        format_table(verdicts)
    )


@pytest.mark.parametrize(
    ("faults", "part", "caught"),
    [
        (Faults(mount_sign=True), "paper", "paper.model2.z_rms_pct_depth"),
        (Faults(double_renders=True), "ideal", "ideal.model2.renders_per_point"),
    ],
)
def test_an_injected_regression_is_caught(
    stored, clean, faults: Faults, part: str, caught: str
) -> None:
    baseline, tolerances = stored
    seed = load_json(BASELINE)["seed"]
    metrics = suite(seed=seed, faults=faults, parts=(part,))
    verdicts = {v.metric: v for v in compare(metrics, baseline, tolerances)}
    assert verdicts[caught].regressed
    # The same part without the fault passes: the fault, not noise, is caught.
    passed = {v.metric: v for v in compare(clean, baseline, tolerances)}
    assert not passed[caught].regressed
