"""One-step fixation with independent eyes: the procedure on the shipped head through the
runner, and the estimator (headsim.estimators.fixation) on exact synthetic angles."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

from headsim.codec import encode
from headsim.estimators.fixation import fixation
from headsim.estimators.result import Flag, Method, Uncertainty
from headsim.geometry.heads import fixating_eye_angles
from headsim.procedures.fixation import FixationResult
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario

#: An ideal head with a motor per eye, no image noise, three listed targets.
IDEAL_FIXATION = """
description = "fixation on an ideal head"
seed = 0

[head]
model = "independent_eyes"
preset = "ideal"

[experiment]
procedure = "fixation"

[[scene.targets]]
name = "near"
position_head_m = [0.04, 0.02, 0.5]

[[scene.targets]]
name = "far_left"
position_head_m = [-0.12, -0.04, 1.2]

[[scene.targets]]
name = "right"
position_head_m = [0.1, 0.03, 0.8]
"""
#: Largest error, % of depth: measured 0.0143, 0.0272, 0.0032 % (encoder counts, servo
#: residuals at z^2 / D per rad), bounded with a margin of about 2.
BOUND_PCT = 0.05
EXACT = 1e-12
D = 0.15


def test_fixation_on_an_ideal_head_measures_every_target(tmp_path: Path) -> None:
    path = tmp_path / "fixation.toml"
    path.write_text(textwrap.dedent(IDEAL_FIXATION))
    result = run_scenario(load_scenario(path, fast=True))
    assert result.ok, result.failures
    assert result.experiment == FixationResult() and encode(result.experiment) == {}
    rows = result.measurements
    assert [r.name for r in rows] == ["near", "far_left", "right"]
    assert all(r.ok for r in rows), [r.status for r in rows]
    assert {r.measurement.method for r in result.records} == {Method.FIXATION}
    worst = max(r.error_pct_of_depth for r in rows)
    assert worst < BOUND_PCT, [r.error_pct_of_depth for r in rows]


POINTS = np.array([[0.04, 0.0, 0.5], [-0.12, 0.0, 1.2], [0.3, 0.0, 0.4], [0.0, 0.0, 3.0]])


@pytest.mark.parametrize("alpha_e", [(0.0, 0.0), (0.0578, -0.0254)])
def test_estimator_recovers_points_from_exact_angles(alpha_e: tuple[float, float]) -> None:
    angles = fixating_eye_angles(POINTS, D, alpha_e)
    estimate = fixation(angles.inward1_rad, angles.inward2_rad, D, alpha_e=alpha_e)
    assert estimate.valid.all() and (estimate.flags == 0).all()
    np.testing.assert_allclose(estimate.positions, POINTS, rtol=0, atol=EXACT)


def test_estimator_recovers_points_with_line_of_sight_offsets() -> None:
    offsets = (0.002, -0.001)
    angles = fixating_eye_angles(POINTS, D, los_offset_m=offsets)
    estimate = fixation(angles.inward1_rad, angles.inward2_rad, D, los_offset_m=offsets)
    np.testing.assert_allclose(estimate.positions, POINTS, rtol=0, atol=EXACT)


def test_parallel_and_diverging_lines_are_invalid() -> None:
    alpha1 = np.array([0.0, -0.1, 0.05, 0.1])
    alpha2 = np.array([0.0, 0.05, -0.1, 0.1])  # parallel, diverging, diverging, converging
    estimate = fixation(alpha1, alpha2, D)
    assert estimate.valid.tolist() == [False, False, False, True]
    assert (estimate.flags[:3] & Flag.NOT_CONVERGING).all()
    assert np.isnan(estimate.positions[:3]).all()
    assert np.isfinite(estimate.positions[3]).all()


def test_covariance_is_finite_and_positive_for_x_and_z() -> None:
    angles = fixating_eye_angles(POINTS, D)
    estimate = fixation(
        angles.inward1_rad,
        angles.inward2_rad,
        D,
        uncertainty=Uncertainty(baseline=1e-4, encoder=1e-4),
    )
    assert estimate.covariance is not None
    cov = estimate.covariance
    assert np.isfinite(cov).all()
    assert (cov[:, 0, 0] > 0).all() and (cov[:, 2, 2] > 0).all()
    np.testing.assert_allclose(cov, np.swapaxes(cov, 1, 2), rtol=0, atol=1e-18)
    # Depth's spread grows with depth (z^2 / D per encoder error): far beyond near.
    assert cov[3, 2, 2] > 10 * cov[0, 2, 2]
