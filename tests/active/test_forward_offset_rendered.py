"""Rendered: a forward (nodal) offset alone changes no estimate at the principal point's column.

The same four targets are measured with Model 2 through the real servo on two
paper heads, one with its optical centres 20 mm in front of the yaw axes and one
without.  With the goal columns (and reference rows) at the principal point the
line of sight through the goal column is the optical axis, which passes through
the yaw axis, so the estimates differ only by what the servo leaves; with the
paper's image-centre goal columns they differ by the first-order effective
baseline change ``D (s1 - s2) / D`` (s_i = -n sin t_i).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge
from headsim.active.model2 import measure_model2
from headsim.geometry.kinematics import head_to_world
from headsim.runs.targets import marker_target
from headsim.sim.settings import HeadSettings, preset
from headsim.sim.simulator import HeadSim
from headsim.studies.error_budget import first_order_offsets

TARGETS_HEAD_M = np.array(
    [[0.05, 0.03, 0.45], [-0.08, -0.04, 0.7], [0.1, 0.05, 1.0], [-0.12, 0.08, 1.3]]
)
NODAL_M = 0.02


def _head(nodal_m: float) -> HeadSettings:
    base = preset("paper")  # no image noise, no joint errors: the offset alone
    return replace(base, cameras=tuple(replace(c, nodal_offset_m=nodal_m) for c in base.cameras))


def _measure(settings: HeadSettings, goal: str) -> tuple[np.ndarray, np.ndarray]:
    """Estimates (N, 3) in H, m, and each servo's final |u - u_i0| (N, 2), px."""
    estimates, residuals = [], []
    with HeadSim("default", settings) as sim:
        cams = [sim.camera_settings(c) for c in (1, 2)]
        if goal == "principal":
            u0 = (cams[0].principal[0], cams[1].principal[0])
            v0 = (cams[0].principal[1], cams[1].principal[1])
        else:  # the paper's: the image centre
            u0, v0 = (None, None), (None, None)
        # The head's calibrated knowledge, exact here so that only the offset acts:
        # each goal column's initial direction, no line-of-sight offsets.
        alpha_e = tuple(sim.effective_initial_direction(c, u0[c - 1]) for c in (1, 2))
        knowledge = HeadKnowledge(alpha_e=alpha_e, u0=u0, v0=v0, los_offset_m=(0.0, 0.0))
        servo = EyeServo(sim)
        for p in TARGETS_HEAD_M:
            world = head_to_world(p[None], 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)[0]
            sim.set_body_pose("marker_red", world)
            m = measure_model2(sim, servo, marker_target("marker_red", "marker_red"), knowledge)
            assert m.ok, m.status
            estimates.append(m.estimate_head_m)
            residuals.append(np.abs(m.servo_residual_px))
    return np.array(estimates), np.array(residuals)


def test_a_forward_offset_alone_changes_no_estimate_at_the_principal_column() -> None:
    plain, offset = _head(0.0), _head(NODAL_M)
    est0, res0 = _measure(plain, "principal")
    est1, res1 = _measure(offset, "principal")
    # What the servo's residuals allow (eqs. 17 and 19 with d alpha = residual / kx):
    kx = np.array([c.kx for c in plain.cameras])
    d_alpha = (res0 + res1) / kx  # (N, 2): both runs' residuals, rad
    x, z, big_d = TARGETS_HEAD_M[:, 0], TARGETS_HEAD_M[:, 2], plain.baseline_m
    t1, t2 = (x + big_d / 2) / z, (big_d / 2 - x) / z
    c1, c2 = (1 + t1**2) / (t1 + t2), (1 + t2**2) / (t1 + t2)
    dz_allowed = z * (c1 * d_alpha[:, 0] + c2 * d_alpha[:, 1])
    dx_allowed = z * (np.abs(c1 * t1 - (1 + t1**2)) * d_alpha[:, 0] + c2 * t1 * d_alpha[:, 1])
    diff = est1 - est0
    assert (np.abs(diff[:, 2]) <= dz_allowed).all(), (diff, dz_allowed)
    assert (np.abs(diff[:, 0]) <= dx_allowed).all(), (diff, dx_allowed)
    # Under 0.1 % of depth, out to 1.3 m (a 0.1 px residual there allows 1.3 mm in z).
    assert (np.abs(diff).max(axis=1) < 1e-3 * TARGETS_HEAD_M[:, 2]).all(), diff

    # The paper's goal columns, off the principal point: the same offset now acts as
    # a baseline change, and moves every depth by the first-order amount.
    centre0, _ = _measure(plain, "centre")
    centre1, _ = _measure(offset, "centre")
    s1, s2 = first_order_offsets(offset)
    predicted_dz = z * (s1 - s2) / big_d
    assert np.abs(predicted_dz).min() > 2e-3  # millimetres: a visible effect
    np.testing.assert_allclose(centre1[:, 2] - centre0[:, 2], predicted_dz, rtol=0.15)
    # Target by target, the offset's effect stands well clear of the servo's residual.
    assert (np.abs(centre1 - centre0)[:, 2] > 5 * np.abs(diff[:, 2])).all()


SCENARIO = """
description = "Model 2 on the paper's cameras, servoing on given goal columns"
seed = 0

[head]
preset = "paper"

[experiment]
procedure = "model2"
goal_columns_px = [303.8, 345.1] # the paper cameras' principal points' columns

[scene.random_targets]
count = 3
depth_m = [0.4, 1.2]
lateral = 0.1
vertical = 0.05
"""


def _scenario_estimates(path, overrides) -> np.ndarray:
    from headsim.runs.runner import run_scenario
    from headsim.scenario.loading import load_scenario

    result = run_scenario(load_scenario(path, overrides=overrides))
    assert result.ok, result.failures
    return np.array([r.measurement.estimate_head_m for r in result.records])


def test_goal_columns_from_a_scenario_make_a_forward_offset_change_no_estimate(tmp_path) -> None:
    path = tmp_path / "goals.toml"
    path.write_text(SCENARIO)
    nodal = {"cam1.nodal_offset_m": NODAL_M, "cam2.nodal_offset_m": NODAL_M}
    at_principal = _scenario_estimates(path, {}) - _scenario_estimates(path, nodal)
    assert np.abs(at_principal).max() < 5e-4  # within what the servo leaves
    centre = {"experiment.goal_columns_px": [319.5, 319.5]}  # the image centres, the paper's
    at_centre = _scenario_estimates(path, centre) - _scenario_estimates(path, centre | nodal)
    assert np.abs(at_centre[:, 2]).min() > 2e-3  # millimetres of depth


def test_a_goal_column_outside_the_image_names_its_key(tmp_path) -> None:
    from headsim.scenario.loading import load_scenario
    from headsim.scenario.tables import ScenarioError

    path = tmp_path / "goals.toml"
    path.write_text(SCENARIO.replace("[303.8, 345.1]", "[303.8, 700.0]"))
    with pytest.raises(ScenarioError, match=r"goal_columns_px\[1\]: 700 px is outside camera 2"):
        load_scenario(path)
