"""The tape measure's noise reaches the calibration: its errors move the fits' figures.

``headsim.active.calibration.tape_measure`` is the one place the calibration
targets' measured positions get their errors; :func:`calibrate_head` calls it
for every target fixated.  With the noise applied, each fit's residuals
scatter as the configured noise and its stated standard errors cover the
truth; were it dropped, the residuals would fall to the servo's own scatter
(about 0.1 mm) and the errors far inside the stated ones.  Every bound is the
0.1 % or 99.9 % point of its statistic's chi-square law.  The pure-math tests
fixate with the exact forward model (headsim.geometry.synthetic): the tape is
the only error there.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import chi2

from headsim.active.calibration import calibrate_head, tape_measure
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import body_target
from headsim.active.placement import calibration_layout
from headsim.estimators.calibration import calibrate_initial_directions, calibrate_lines_of_sight
from headsim.geometry.sampling import sample_points_head
from headsim.geometry.synthetic import StereoHead, fixation_angles
from headsim.paper import BASELINE_M, INITIAL_DIRECTIONS_RAD
from headsim.sim import names
from headsim.sim.settings import ideal_head
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))
HEAD = StereoHead(
    BASELINE_M, alpha_e1=INITIAL_DIRECTIONS_RAD[0], alpha_e2=INITIAL_DIRECTIONS_RAD[1]
)


def _within_chi2(statistic: float, dof: int) -> tuple[float, float]:
    """The 0.1 % and 99.9 % points of chi-square with ``dof`` degrees; asserts ``statistic`` lies between."""
    lo, hi = chi2.ppf([0.001, 0.999], dof)
    assert lo < statistic < hi, (
        f"chi-square {statistic:.3g} outside [{lo:.3g}, {hi:.3g}] ({dof} dof)"
    )
    return lo, hi


def _layout(rng: np.random.Generator, n: int) -> np.ndarray:
    """A calibration layout in H as the scenarios draw it: 0.25-0.6 m, |x/z| <= 0.16, |y/z| <= 0.08."""
    return sample_points_head(rng, n, (-0.16, 0.16), (-0.08, 0.08), depth_range_m=(0.25, 0.6))


def _measured(
    rng: np.random.Generator, truth: np.ndarray, sigma_p: float, sigma_d: float
) -> np.ndarray:
    return np.array(
        [tape_measure(p, rng, position_noise_m=sigma_p, depth_noise_m=sigma_d) for p in truth]
    )


# -- the tape itself --------------------------------------------------------------


def test_the_tapes_errors_have_the_configured_spread_on_each_coordinate() -> None:
    rng = np.random.default_rng(1)
    truth = _layout(rng, 400)
    sigma_p, sigma_d = 1e-3, 3e-3
    error = _measured(rng, truth, sigma_p, sigma_d) - truth
    # x_h, y_h: the position noise; z_h: the position and depth noise together.
    for column, sigma in ((0, sigma_p), (1, sigma_p), (2, math.hypot(sigma_p, sigma_d))):
        _within_chi2(float(np.sum((error[:, column] / sigma) ** 2)), len(truth))
    # Independent coordinates: no correlation beyond sampling (4 sigma of 1 / sqrt(n)).
    assert np.abs(np.corrcoef(error.T)[np.triu_indices(3, 1)]).max() < 4 / math.sqrt(len(truth))


def test_an_exact_tape_returns_the_truth_and_draws_nothing() -> None:
    rng = np.random.default_rng(2)
    before = rng.bit_generator.state
    point = np.array([0.01, -0.02, 0.4])
    measured = tape_measure(point, rng)
    assert np.array_equal(measured, point) and measured is not point
    assert rng.bit_generator.state == before  # the other streams stay as they were


# -- the fits on exact geometry: the tape is the only error ------------------------


def test_sec_v_depth_residuals_scatter_as_the_tape_and_its_standard_errors_cover_the_truth() -> (
    None
):
    rng = np.random.default_rng(3)
    sigma_p, sigma_d = 1e-3, 2e-3
    sigma_z = math.hypot(sigma_p, sigma_d)
    seeds, n = 40, 20
    scatter = coverage = 0.0
    for _ in range(seeds):
        truth = _layout(rng, n)
        fix = fixation_angles(HEAD, truth)
        z = _measured(rng, truth, sigma_p, sigma_d)[:, 2]
        fit = calibrate_initial_directions(
            fix.alpha1, fix.alpha2, z, BASELINE_M, sigma_depth=sigma_z
        )
        scatter += float(np.sum((fit.depth_residuals / sigma_z) ** 2))
        error = fit.alpha_e - np.array(INITIAL_DIRECTIONS_RAD)
        coverage += float(error @ np.linalg.solve(fit.covariance, error))
    print(
        f"depth residuals: rms {math.sqrt(scatter / (seeds * (n - 2))) * sigma_z * 1e3:.3f} mm, tape {sigma_z * 1e3:.3f} mm"
    )
    _within_chi2(scatter, seeds * (n - 2))
    _within_chi2(coverage, 2 * seeds)


def test_line_of_sight_residuals_scatter_as_the_tape_and_its_standard_errors_cover_the_truth() -> (
    None
):
    rng = np.random.default_rng(4)
    sigma_p = 1e-3
    seeds, n = 20, 30
    truth_params = np.r_[INITIAL_DIRECTIONS_RAD, 0.0, 0.0]
    scatter = coverage = 0.0
    for _ in range(seeds):
        truth = _layout(rng, n)
        fix = fixation_angles(HEAD, truth)
        measured = _measured(rng, truth, sigma_p, 0.0)
        fit = calibrate_lines_of_sight(
            fix.alpha1, fix.alpha2, measured, BASELINE_M, sigma_position=sigma_p, sigma_encoder=0.0
        )
        assert fit.separable, fit.message
        # Each line's residual is the tape's (x_h, z_h) error across it: (cos a1, -sin a1) and
        # (cos a2, sin a2), each of variance sigma_p^2, correlated by cos(a1 + a2).
        a1 = fix.alpha1 + fit.alpha_e[0]
        a2 = fix.alpha2 + fit.alpha_e[1]
        rho = np.cos(a1 + a2)
        r1, r2 = fit.residuals_m.T / sigma_p
        scatter += float(np.sum((r1 * r1 - 2 * rho * r1 * r2 + r2 * r2) / (1 - rho * rho)))
        error = np.r_[fit.alpha_e, fit.offset_m] - truth_params
        coverage += float(error @ np.linalg.solve(fit.covariance, error))
    _within_chi2(scatter, seeds * (2 * n - 4))
    _within_chi2(coverage, 4 * seeds)


# -- the product's path: a rendered calibration ------------------------------------


def test_a_rendered_calibrations_residuals_scatter_as_its_tape() -> None:
    # Depth noise well above the position noise: each reaches its own figure.
    sigma_p, sigma_d = 1e-3, 4e-3
    sigma_z = math.hypot(sigma_p, sigma_d)
    with HeadSim("default", ideal_head()) as sim:
        layout = calibration_layout(sim.stereo_views(), np.random.default_rng(5), 12)
        run = calibrate_head(
            sim,
            EyeServo(sim),
            BALL,
            names.CALIBRATION_BALL,
            layout,
            depth_noise_m=sigma_d,
            position_noise_m=sigma_p,
            rng=np.random.default_rng(6),
        )
    n = run.samples
    assert n >= 10
    depth = float(np.sum((run.fit.depth_residuals / sigma_z) ** 2))
    assert run.vertical is not None
    heights = [float(np.sum((v.residuals_m / sigma_p) ** 2)) for v in run.vertical]
    rms = [
        float(np.sqrt(np.mean(r**2))) * 1e3
        for r in (run.fit.depth_residuals, *(v.residuals_m for v in run.vertical))
    ]
    print(f"{n} balls: depth residuals rms {rms[0]:.2f} mm (tape {sigma_z * 1e3:.2f}), "
          f"heights {rms[1]:.2f}, {rms[2]:.2f} mm (tape {sigma_p * 1e3:.2f})")  # fmt: skip
    _within_chi2(depth, n - 2)
    for statistic in heights:
        _within_chi2(statistic, n - 2)
