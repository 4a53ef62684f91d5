"""The principal point as a zoom's fixed point, and the active method servoing to it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.active.calibration import calibrate_head
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, body_target
from headsim.active.model2 import measure_model2
from headsim.active.placement import calibration_layout
from headsim.active.principal import (
    PrincipalPointError,
    fixed_point_of_zoom,
    principal_points_by_zoom,
    zoomed,
)
from headsim.sim import names
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))
BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))


def test_fixed_point_of_a_synthetic_zoom_is_recovered(rng) -> None:
    centre, scale = np.array([303.8, 306.3]), 1.5
    before = rng.uniform([100, 80], [540, 400], size=(48, 2))
    after = centre + scale * (before - centre)
    exact = fixed_point_of_zoom(before, after)
    np.testing.assert_allclose(exact.principal_px, centre, atol=1e-9)
    assert exact.scale == pytest.approx(scale, abs=1e-12)
    assert exact.residual_rms_px < 1e-9
    # Corner-like noise (0.05 px) on both images: the centre to a few hundredths of a pixel,
    # and the stated standard error is of the right size.
    errors, stds = [], []
    for _ in range(200):
        noisy = fixed_point_of_zoom(
            before + rng.normal(0, 0.05, before.shape), after + rng.normal(0, 0.05, after.shape)
        )
        errors.append(noisy.principal_px - centre)
        stds.append(noisy.std_px)
    spread = np.std(errors, axis=0)
    assert np.all(spread < 0.05)
    np.testing.assert_allclose(np.mean(stds, axis=0), spread, rtol=0.5)


def test_no_zoom_or_too_few_features_is_a_clear_error(rng) -> None:
    points = rng.uniform(0, 640, size=(10, 2))
    with pytest.raises(PrincipalPointError, match="no zoom"):
        fixed_point_of_zoom(points, points + 0.3)
    with pytest.raises(PrincipalPointError, match="at least 3 matched features, got 2"):
        fixed_point_of_zoom(points[:2], points[:2] * 1.5)
    with pytest.raises(PrincipalPointError, match=r"must both be \(N, 2\)"):
        fixed_point_of_zoom(points, points[:5])


def test_rendered_chessboards_give_the_papers_off_centre_principal_points() -> None:
    with (
        HeadSim("chessboard", paper_head()) as before,
        HeadSim("chessboard", zoomed(paper_head(), 1.3)) as after,
    ):
        run = principal_points_by_zoom(before, after, 1.3, np.random.default_rng(0), poses=1)
        with pytest.raises(
            ValueError, match=r"after\.settings must be before\.settings zoomed 1\.5x"
        ):
            principal_points_by_zoom(before, after, 1.5)
    assert run.views == 1 and run.renders == 4
    # (303.8, 306.3) and (345.1, 197.3): off the image centre by up to 67 px.
    assert np.abs(run.errors_px).max() < 0.15
    for fit in run.fits:
        assert fit.scale == pytest.approx(1.3, abs=1e-3)
        assert fit.residual_rms_px < 0.2  # radial distortion scales about the same point


def test_the_principal_column_points_along_the_mount_yaw() -> None:
    cams = (
        CameraSettings(cx=300.0, cy=250.0, mount_yaw_rad=0.03, k1=-0.2),
        CameraSettings(cx=330.0, mount_yaw_rad=-0.02),
    )
    with HeadSim("default", HeadSettings(cameras=cams)) as sim:
        for camera, cam in zip((1, 2), cams, strict=True):
            # On every row: a radial lens keeps x = 0 on the principal column.
            assert sim.effective_initial_direction(camera, cam.principal[0]) == pytest.approx(
                cam.mount_yaw_rad, abs=1e-12
            )
        # The image centre's column adds the angle of its ray off the axis.
        assert sim.effective_initial_direction(2, 319.5) == sim.effective_initial_direction(2)
        assert sim.effective_initial_direction(2) == pytest.approx(
            -0.02 - np.arctan((319.5 - 330.0) / cams[1].kx), abs=1e-12
        )


def test_servoing_on_the_fixed_point_keeps_the_calibration_through_a_zoom() -> None:
    head = paper_head()
    with (
        HeadSim("chessboard", head) as before,
        HeadSim("chessboard", zoomed(head, 1.3)) as after,
    ):
        found = principal_points_by_zoom(before, after, 1.3, np.random.default_rng(1), poses=1)
    columns = (found.principal_px[0][0], found.principal_px[1][0])
    p_head = np.array([0.06, 0.02, 0.8])
    with HeadSim("default", head) as sim:
        positions = calibration_layout(sim.stereo_views(), np.random.default_rng(2), 16)
        run = calibrate_head(
            sim,
            EyeServo(sim),
            BALL,
            names.CALIBRATION_BALL,
            positions,
            knowledge=HeadKnowledge(u0=columns),
        )
        assert run.samples >= 12
        mount = np.array([c.mount_yaw_rad for c in head.cameras])
        np.testing.assert_allclose(run.truth_alpha_e, mount, atol=2e-4)  # column within 0.15 px
        assert np.abs(run.alpha_e_error).max() < 5e-4
        assert run.knowledge.u0 == columns
        ratios = [c.kx / c.ky for c in head.cameras]
        np.testing.assert_allclose(run.knowledge.kx_over_ky, ratios, atol=0.01)
    # The plain method with perfectly known effective directions, for contrast.
    with HeadSim("default", head) as sim:
        plain = HeadKnowledge(
            alpha_e=(sim.effective_initial_direction(1), sim.effective_initial_direction(2))
        )
    errors = {}
    for zoom in (1.0, 1.5):
        with HeadSim("default", zoomed(head, zoom)) as sim:
            sim.set_body_pose(RED.name, sim.transform_points(p_head, "head", "world")[0])
            fixed = measure_model2(sim, EyeServo(sim), RED, run.knowledge)
            centre = measure_model2(sim, EyeServo(sim), RED, replace(plain, v0=run.knowledge.v0))
            assert fixed.ok and centre.ok
            errors[zoom] = (fixed.error_pct_of_depth, centre.error_pct_of_depth)
    assert errors[1.0][0] < 0.1 and errors[1.5][0] < 0.1
    assert errors[1.0][1] < 0.3
    assert errors[1.5][1] > 3.0  # the image centre's ray turned by ~6 and ~10 mrad
