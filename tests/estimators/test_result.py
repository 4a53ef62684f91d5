"""The estimators' shared types and entry checks (estimators/result.py), exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.estimators.result import (
    Flag,
    PositionEstimate,
    Uncertainty,
    as_pixels,
    as_vector,
    check_angles,
    check_baseline,
)


def test_the_fatal_flags_are_the_four_that_leave_no_position() -> None:
    fatal = Flag.fatal()
    assert fatal == Flag.NONFINITE | Flag.NOT_CONVERGING | Flag.BEHIND_CAMERA | Flag.NO_Y
    assert not fatal & (Flag.SMALL_U1D | Flag.SMALL_U2D)  # degraded, still a position
    assert len({int(f) for f in Flag if f}) == 6  # one bit each


def test_uncertainty_refuses_a_bad_deviation_and_quantises_exactly() -> None:
    with pytest.raises(ValueError, match=r"Uncertainty\.pixel must be a finite"):
        Uncertainty(pixel=-0.1)
    with pytest.raises(ValueError, match=r"Uncertainty\.baseline"):
        Uncertainty(baseline=math.inf)
    unc = Uncertainty.quantised(1e-3, pixel=0.2)
    assert unc == Uncertainty(baseline=0.0, encoder=1e-3 / math.sqrt(12.0), pixel=0.2)


def test_to_world_maps_points_and_rotates_covariances_by_the_neck() -> None:
    # Neck at rest: H's x is W's x, H's z (forward) is W's y, H's y is W's -z; the origin
    # is a2 + d1 above W's.
    d1, a2 = 0.12, 0.09
    covariance = np.diag([1.0, 2.0, 3.0])[None]
    estimate = PositionEstimate(
        np.array([[0.1, 0.2, 0.7]]), np.array([True]), np.array([0]), covariance
    )
    world = estimate.to_world(0.0, 0.0, d1, a2)
    assert world.frame == "W" and world.valid.tolist() == [True]
    np.testing.assert_allclose(world.positions, [[0.1, 0.7, a2 + d1 - 0.2]], atol=1e-15)
    np.testing.assert_allclose(world.covariance, np.diag([1.0, 3.0, 2.0])[None], atol=1e-15)
    # Turned: the covariance keeps its eigenvalues.
    turned = estimate.to_world(0.4, -0.3, d1, a2)
    assert turned.covariance is not None
    np.testing.assert_allclose(np.linalg.eigvalsh(turned.covariance[0]), [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="head frame H, this one is in W"):
        world.to_world(0.0, 0.0, d1, a2)
    assert estimate.reasons(0) is Flag.NONE


def test_the_entry_checks_shape_inputs_and_name_the_bad_one() -> None:
    assert as_vector(0.5, "alpha1").shape == (1,)
    with pytest.raises(ValueError, match=r"alpha1 must be a scalar or have shape \(N,\)"):
        as_vector(np.zeros((2, 2)), "alpha1")
    np.testing.assert_array_equal(as_pixels((3.0, 4.0), "uv1", 1), [[3.0, 4.0]])
    with pytest.raises(ValueError, match=r"uv2 must have shape \(2, 2\)"):
        as_pixels(np.zeros((3, 2)), "uv2", 2)
    check_angles(np.array([math.pi, -math.pi]), "alpha2")  # the bound itself is allowed
    with pytest.raises(ValueError, match="alpha2 must be in radians"):
        check_angles(np.array([0.1, 3.2]), "alpha2")
    assert check_baseline(np.float32(0.15)) == pytest.approx(0.15) and isinstance(
        check_baseline(0.15), float
    )
    for bad in (0.0, 10.0, 150.0, math.nan):
        with pytest.raises(ValueError, match="baseline must be in metres"):
            check_baseline(bad)
