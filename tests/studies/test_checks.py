"""The bench's comparison with the baseline: direction, tolerances, new and non-finite metrics."""

from __future__ import annotations

import math

import pytest

from headsim.studies.checks import BASELINE, TOLERANCES, compare, format_table, load_json

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
