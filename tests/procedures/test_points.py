"""Model 1 or 2 on each target; the calibration procedure's check targets before and after."""

from __future__ import annotations

from collections.abc import Callable

from headsim.estimators.result import Method
from headsim.run.outcomes import PointsResult, RunResult


def test_check_targets_are_far_better_after_the_calibration(
    fast_run: Callable[[str], RunResult],
) -> None:
    result = fast_run("calibration")
    assert result.ok, result.failures
    assert isinstance(result.experiment, PointsResult)
    checks = result.experiment.check_targets
    assert checks is not None and len(checks) == len(result.records) // 2 > 0
    for check in checks:
        assert check.error_m_calibrated < 0.01 * check.error_m_uncalibrated
    assert [r.knowledge for r in result.records[:2]] == ["none", "calibrated"]


def test_plain_points_have_no_check_targets(fast_run: Callable[[str], RunResult]) -> None:
    result = fast_run("quickstart")
    assert result.ok, result.failures
    assert result.experiment == PointsResult()
    assert {r.measurement.method for r in result.records} == {Method.MODEL2}
