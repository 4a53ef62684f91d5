"""The regression bench: its comparison rules, and that it catches injected regressions."""

from __future__ import annotations

import math

import pytest

from headsim.studies.bench import Faults, suite
from headsim.studies.bench_compare import BASELINE, TOLERANCES, compare, format_table, load_json

RULES = {
    "err": {"worse": "higher", "abs": 0.1, "rel": 0.5},
    "good": {"worse": "lower", "abs": 1.0},
}


def test_compare_applies_direction_and_abs_plus_rel_tolerance() -> None:
    verdicts = {
        v.metric: v
        for v in compare({"err": 1.55, "good": 98.9}, {"err": 1.0, "good": 100.0}, RULES)
    }
    assert verdicts["err"].allowed == pytest.approx(0.6)
    assert not verdicts["err"].regressed  # 0.55 worse, 0.6 allowed
    assert verdicts["good"].regressed  # 1.1 lower, 1.0 allowed
    assert verdicts["err"].change == pytest.approx(0.55)
    better = {
        v.metric: v
        for v in compare({"err": 0.1, "good": 200.0}, {"err": 1.0, "good": 100.0}, RULES)
    }
    assert not any(v.regressed for v in better.values())


def test_new_metrics_and_non_finite_values() -> None:
    verdicts = {v.metric: v for v in compare({"err": math.inf, "fresh": 3.0}, {"err": 1.0}, RULES)}
    assert verdicts["err"].regressed
    assert verdicts["fresh"].label == "new" and not verdicts["fresh"].regressed
    table = format_table(list(verdicts.values()))
    assert "REGRESSED" in table and "new" in table


def test_every_baseline_metric_has_a_tolerance() -> None:
    baseline, tolerances = load_json(BASELINE), load_json(TOLERANCES)
    assert baseline.get("history"), "the baseline records why it was set"
    assert set(baseline["metrics"]) == set(tolerances)
    for rule in tolerances.values():
        assert rule["worse"] in ("higher", "lower")


@pytest.fixture(scope="module")
def stored() -> tuple[dict, dict]:
    return load_json(BASELINE)["metrics"], load_json(TOLERANCES)


def test_the_suite_passes_on_this_code(stored) -> None:
    baseline, tolerances = stored
    metrics = suite(seed=load_json(BASELINE)["seed"])
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
def test_an_injected_regression_is_caught(stored, faults: Faults, part: str, caught: str) -> None:
    baseline, tolerances = stored
    seed = load_json(BASELINE)["seed"]
    metrics = suite(seed=seed, faults=faults, parts=(part,))
    verdicts = {v.metric: v for v in compare(metrics, baseline, tolerances)}
    assert verdicts[caught].regressed
    # The same part without the fault passes: the fault, not noise, is caught.
    clean = {v.metric: v for v in compare(suite(seed=seed, parts=(part,)), baseline, tolerances)}
    assert not clean[caught].regressed
