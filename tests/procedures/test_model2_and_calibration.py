"""Model 2 on each target; the calibration procedure's check targets before and after."""

from __future__ import annotations

from collections.abc import Callable

from headsim.codec import encode
from headsim.estimators.result import Method
from headsim.procedures.calibration import CalibrationCheck
from headsim.procedures.model2 import Model2Result
from headsim.runs.result import RunResult


def test_check_targets_are_far_better_after_the_calibration(
    fast_run: Callable[[str], RunResult],
) -> None:
    result = fast_run("calibration")
    assert result.ok, result.failures
    assert isinstance(result.experiment, CalibrationCheck)
    checks = result.experiment.check_targets
    assert len(checks) == len(result.records) // 2 > 0
    for check in checks:
        assert check.error_m_calibrated < 0.01 * check.error_m_uncalibrated
    assert [r.knowledge for r in result.records[:2]] == ["none", "calibrated"]
    assert result.experiment.summary_lines(False)[0].startswith("Check targets:")


def test_model2_adds_nothing_beyond_its_measurements(
    fast_run: Callable[[str], RunResult],
) -> None:
    result = fast_run("quickstart")
    assert result.ok, result.failures
    assert result.experiment == Model2Result() and encode(result.experiment) == {}
    assert {r.measurement.method for r in result.records} == {Method.MODEL2}
