"""Where the calibration balls go: the near/far design for the line-of-sight offsets."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.estimators.calibration import calibrate_lines_of_sight
from headsim.geometry.camera_model import PinholeCamera
from headsim.geometry.kinematics import world_to_head
from headsim.geometry.synthetic import StereoHead, observe, quantise
from headsim.runs.runner import calibrate_scenario
from headsim.scenario.calibration_design import near_far_depths, near_fraction, offset_std_limit
from headsim.scenario.loading import load_scenario
from headsim.scenario.tables import ScenarioError

RANGE_M = (0.25, 1.5)


def test_the_near_share_b_over_a_plus_b_minimises_the_offset_limit() -> None:
    a, b = RANGE_M
    depths = near_far_depths(60, RANGE_M)
    assert near_fraction(RANGE_M) == pytest.approx(b / (a + b))
    assert (depths == a).sum() == 51 and (depths == b).sum() == 9
    # Eq. (1) at p = b / (a + b) is sigma (a + b) / ((b - a) sqrt(n)) (exact for 51/9 of 60:
    # 51/60 = 0.85 is the rounding of 6/7).
    limit = offset_std_limit(depths, 1e-3)
    assert limit == pytest.approx(1e-3 * (a + b) / ((b - a) * math.sqrt(60)), rel=0.01)
    for share in (0.5, 0.7, 0.95):  # any other split is worse
        assert offset_std_limit(near_far_depths(60, RANGE_M, share), 1e-3) > limit
    uniform = offset_std_limit(np.linspace(a, b, 60), 1e-3)
    assert limit < 0.56 * uniform  # 0.18 mm against 0.34 mm
    with pytest.raises(ValueError, match="near_fraction"):
        near_far_depths(60, RANGE_M, 1.0)


def _stated_and_scatter(layout: str, seeds: int) -> tuple[float, float]:
    """The extended fit on the exact forward model: mean stated std and RMS error of s1, m."""
    cam = PinholeCamera(640, 480, 834.83, 815.42, 303.8, 306.3, 0.0, 0.0)
    head = StereoHead(0.150, cam, cam, 0.05, -0.02, nodal1=0.02, nodal2=0.02, side1=1e-3)
    truth = head.line_of_sight_offsets()[0]
    stated, errors = [], []
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        z = rng.uniform(*RANGE_M, 60) if layout == "uniform" else near_far_depths(60, RANGE_M)
        p = np.column_stack([rng.uniform(-0.16, 0.16, 60) * z, rng.uniform(-0.08, 0.08, 60) * z, z])
        obs = observe(head, p)
        a1, a2 = (quantise(a, head.encoder_resolution) for a in (obs.alpha1, obs.alpha2))
        measured = p + rng.normal(0.0, 1e-3, p.shape)
        fit = calibrate_lines_of_sight(a1, a2, measured, 0.150, sigma_position=1e-3,
                                       sigma_encoder=head.encoder_resolution / math.sqrt(12))  # fmt: skip
        stated.append(fit.std_errors[2])
        errors.append(fit.offset_m[0] - truth)
    return float(np.mean(stated)), float(np.sqrt(np.mean(np.square(errors))))


def test_the_fit_states_and_reaches_the_designs_limit() -> None:
    near_far, scatter = _stated_and_scatter("near_far", 20)
    uniform, _ = _stated_and_scatter("uniform", 20)
    limit = offset_std_limit(near_far_depths(60, RANGE_M), 1e-3)
    assert near_far == pytest.approx(limit, rel=0.1)  # the fit's own std is eq. (1)'s
    assert near_far < 0.6 * uniform
    assert 0.6 * near_far < scatter < 1.4 * near_far  # 20 seeds: the scatter matches it


@pytest.mark.render
def test_a_rendered_near_far_calibration_fixates_every_ball() -> None:
    near_far = {"experiment.calibration.layout": "near_far"}
    scenario = load_scenario("realistic_field", fast=True, overrides=near_far)
    spec = scenario.experiment.calibration
    assert spec is not None and spec.layout == "near_far"
    report = calibrate_scenario(scenario)
    assert report.ok and report.fixated == spec.targets == 12
    assert report.layout is not None and report.lines_of_sight is not None
    settings = scenario.settings
    world = np.array(report.layout.positions_world_m)
    head = world_to_head(world, 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)
    np.testing.assert_allclose(np.sort(head[:, 2]), near_far_depths(12, spec.depth_m), atol=1e-9)
    assert report.layout.kind == "near_far"
    assert report.lines_of_sight.separable


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("layout", "random", r"layout: unknown value .*uniform, near_far"),
        ("near_fraction", 1.0, r"near_fraction: 1 is out of range .*> 0 and < 1"),
    ],
)
def test_a_bad_layout_names_its_key(field, value, message) -> None:
    with pytest.raises(ScenarioError, match=message):
        load_scenario("realistic_field", overrides={f"experiment.calibration.{field}": value})


def test_near_fraction_needs_the_near_far_layout() -> None:
    overrides = {"experiment.calibration.near_fraction": 0.8}  # the file's layout: uniform
    with pytest.raises(ScenarioError, match='near_fraction: given with layout = "uniform"'):
        load_scenario("realistic_field", overrides=overrides)
