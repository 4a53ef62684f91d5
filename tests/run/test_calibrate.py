"""The Sec. V calibration phase: its report, from a rendered run of the quick start."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from scipy.stats import chi2

from headsim.active.failure import Failure, FailureCause
from headsim.estimators.result import Status
from headsim.runs.calibrate import position_outcomes
from headsim.runs.runner import calibrate_scenario
from headsim.scenario.loading import load_scenario


def test_the_quick_start_calibrates_within_its_stated_errors() -> None:
    scenario = load_scenario("quickstart", fast=True)
    spec = scenario.experiment.calibration
    assert spec is not None
    report = calibrate_scenario(scenario)
    assert report.status is Status.OK and report.status_text == "ok"
    assert report.fixated == len(report.positions) == spec.targets
    assert all(p.failure is None and p.status == "ok" for p in report.positions)
    assert report.layout is not None and len(report.layout.positions_world_m) == spec.targets
    assert report.rendered_frames is not None and report.rendered_frames > 0
    assert report.knowledge is not None and report.knowledge.alpha_e_rad is not None
    errors, stds = report.alpha_e_error_rad, report.alpha_e_std_rad
    assert errors is not None and stds is not None
    # A tape measure: within four of the fit's stated standard errors.
    assert all(abs(e) < 4 * s for e, s in zip(errors, stds, strict=True))


def test_each_position_outcome_keeps_its_failure() -> None:
    lost = Failure(FailureCause.LOST, "step 1", 2)
    outcomes = position_outcomes([None, lost])
    assert [o.failure for o in outcomes] == [None, lost]
    assert [o.status for o in outcomes] == ["ok", "Ca2 at step 1: target lost"]


@pytest.mark.parametrize(
    ("position_noise_m", "depth_noise_m"), [(0.002, 0.0), (0.0, 0.002)], ids=["position", "depth"]
)
def test_a_scenarios_tape_noise_reaches_the_fit(
    tmp_path: Path, position_noise_m: float, depth_noise_m: float
) -> None:
    # An ideal head (its servo scatters by about 0.1 mm): the depth residuals are the tape's.
    path = tmp_path / "tape.toml"
    path.write_text(
        'description = "a tape"\n[experiment]\nprocedure = "model2"\n'
        f"[experiment.calibration]\ntargets = 8\nposition_noise_m = {position_noise_m}\n"
        f"depth_noise_m = {depth_noise_m}\n"
        "[[scene.targets]]\nposition_head_m = [0.02, 0.01, 0.6]\n"
    )
    report = calibrate_scenario(load_scenario(path))
    assert report.status is Status.OK and report.depth_residual_rms_m is not None
    n = report.fixated
    sigma_z = math.hypot(position_noise_m, depth_noise_m)
    statistic = n * (report.depth_residual_rms_m / sigma_z) ** 2
    lo, hi = chi2.ppf([0.001, 0.999], n - 2)  # the fit takes 2 of the n degrees
    assert lo < statistic < hi, (statistic, lo, hi)
