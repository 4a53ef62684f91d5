"""Every method's calibration on one head (Zhang, Sec. V, the zoom fixed points) and a
cache that calibrates each head of a study once."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from headsim.active.calibration_report import CalibrationReport
from headsim.active.measurement import HeadKnowledge
from headsim.active.placement import calibration_layout
from headsim.active.principal import (
    PROBE_ZOOM,
    PrincipalPointRun,
    view_scale,
)
from headsim.geometry.stereo_view import StereoView
from headsim.procedures.stereo import StereoResult
from headsim.runs.progress import Progress, quiet
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import start_views
from headsim.stereo.calibration import StereoCalibration
from headsim.studies.methods import METHODS, StudyConfig
from headsim.studies.scenario_runs import calibration_run, zhang_run, zoom_fixed_points_run


@dataclass(frozen=True)
class SecV:
    """A Sec. V calibration run through the runner: what the head learnt and the report."""

    knowledge: HeadKnowledge
    report: CalibrationReport

    @property
    def alpha_e_error_rad(self) -> tuple[float, float]:
        """Each camera's alpha_e minus the truth, rad."""
        errors = self.report.alpha_e_error_rad
        assert errors is not None  # calibration_run raises if the calibration failed
        return (errors[0], errors[1])

    @property
    def truth_alpha_e_rad(self) -> tuple[float, float]:
        """Each camera's true alpha_e on the servo's goal column, rad."""
        truth = self.report.alpha_e_truth_rad
        assert truth is not None  # the report of every calibration that ran has it
        return (truth[0], truth[1])


@dataclass(frozen=True)
class Calibrations:
    """Every method's calibration on one head.

    ``stereo``: the Zhang calibration; ``active``: Sec. V with the servo on
    the image centre (with the extended vertical fit); ``principal``: the
    zoom fixed points; ``fixed_point``: Sec. V with the servo on the fixed
    points' columns.  ``seconds``/``renders``: what calibrating cost.
    """

    settings: HeadSettings
    stereo: StereoCalibration
    active: SecV
    principal: PrincipalPointRun
    fixed_point: SecV
    seconds: float
    renders: int

    def knowledge(self, method: str, refound: PrincipalPointRun | None = None) -> HeadKnowledge:
        """What the head knows about itself when measuring with ``method`` (an active one).

        ``refound``: for ``active_refound``, the fixed points found again on
        the head being measured (its u and v replace the calibrated goal
        columns and v0).
        """
        alpha_e = self.active.knowledge.alpha_e
        if method == "active_v_known":
            return HeadKnowledge(
                alpha_e=alpha_e, v0=(self.stereo.cam1.K[1, 2], self.stereo.cam2.K[1, 2])
            )
        if method == "active_centre":
            return HeadKnowledge(alpha_e=alpha_e)
        if method == "active_extended":
            return self.active.knowledge
        if method == "active_fixed_point":
            return self.fixed_point.knowledge
        if method == "active_refound":
            if refound is None:
                raise ValueError("active_refound needs the fixed points found again (refound)")
            (u1, v1), (u2, v2) = refound.principal_px
            return replace(self.fixed_point.knowledge, u0=(u1, u2), v0=(v1, v2))
        raise ValueError(f"unknown active method {method!r}; allowed: {', '.join(METHODS[1:])}")

    def goal_columns(self) -> tuple[float, float]:
        """The fixed-point servo's goal column per camera, px."""
        (u1, _), (u2, _) = self.principal.principal_px
        return (u1, u2)

    def report(self) -> dict[str, Any]:
        """Each calibration's figures beside the simulator's truth (for JSON)."""
        s = self.stereo
        active, fixed = self.active, self.fixed_point
        mount_yaws = tuple(c.mount_yaw_rad for c in self.settings.cameras)
        return {
            "seconds": self.seconds,
            "renders": self.renders,
            "stereo": {
                "views": s.views,
                "rms_px": s.stereo_rms_px,
                "focal_error_pct": [
                    100 * e for cam in (s.cam1, s.cam2) for e in cam.focal_rel_errors
                ],
                "principal_error_px": [
                    e for cam in (s.cam1, s.cam2) for e in cam.principal_errors_px
                ],
                "k1_error": [s.cam1.k1_error, s.cam2.k1_error],
                "baseline_error_mm": (s.baseline_m - s.true_baseline_m) * 1e3,
                "rotation_error_mrad": s.rotation_error_rad * 1e3,
            },
            "active": {
                "samples": active.report.fixated,
                "renders": active.report.renders.total,
                "alpha_e_rad": active.report.alpha_e_rad,
                "truth_alpha_e_rad": active.truth_alpha_e_rad,
                "alpha_e_error_mrad": [1e3 * e for e in active.alpha_e_error_rad],
                "v0_px": active.knowledge.v0,
                "kx_over_ky": active.knowledge.kx_over_ky,
                "truth_principal_px": [c.principal for c in self.settings.cameras],
                "truth_kx_over_ky": [c.kx / c.ky for c in self.settings.cameras],
            },
            "principal_point": {
                "zoom": self.principal.zoom,
                "recovered_px": self.principal.principal_px,
                "truth_px": self.principal.truth_px,
                "error_px": self.principal.errors_px,
                "std_px": [f.std_px for f in self.principal.fits],
                "scale": [f.scale for f in self.principal.fits],
                "residual_rms_px": [f.residual_rms_px for f in self.principal.fits],
                "renders": self.principal.renders,
            },
            "fixed_point": {
                "samples": fixed.report.fixated,
                "renders": fixed.report.renders.total,
                "goal_columns_px": self.goal_columns(),
                "alpha_e_rad": fixed.report.alpha_e_rad,
                # On the principal point's column the offsets are the mount yaws.
                "truth_alpha_e_rad": fixed.truth_alpha_e_rad,
                "mount_yaw_rad": mount_yaws,
                "alpha_e_error_mrad": [1e3 * e for e in fixed.alpha_e_error_rad],
                "v0_px": fixed.knowledge.v0,
                "kx_over_ky": fixed.knowledge.kx_over_ky,
            },
        }


def zhang_stereo(
    settings: HeadSettings, config: StudyConfig
) -> tuple[StereoCalibration, StereoResult]:
    """Zhang's calibration of ``settings``' pair from ``config.board_poses`` chessboard
    poses (seeded by ``config.seed``), and the stereo run's result (views kept, renders)."""
    scale = view_scale(settings)
    result = zhang_run(settings, config.board_poses, (0.4 * scale, 1.0 * scale), config.seed)
    assert result.calibration is not None  # zhang_run raises otherwise
    return result.calibration, result


def zoom_fixed_points(settings: HeadSettings, config: StudyConfig) -> PrincipalPointRun:
    """The zoom fixed points of ``settings``' cameras, seeded by ``config.seed``."""
    return zoom_fixed_points_run(settings, PROBE_ZOOM, config.principal_poses, config.seed + 1)


def calibration_positions(
    views: Sequence[StereoView], settings: HeadSettings, config: StudyConfig
) -> np.ndarray:
    """The Sec. V ball positions of every method (seeded by ``config.seed``) in the
    ``views`` of the head ``settings`` (e.g. :func:`headsim.sim.simulator.start_views`)."""
    scale = view_scale(settings)
    return calibration_layout(
        views,
        np.random.default_rng(config.seed + 2),
        config.calibration_targets,
        depth_range_m=(0.25 * scale, 0.6 * scale),
        lateral=0.16 / scale,
    )


def calibrate_methods(
    settings: HeadSettings, config: StudyConfig, progress: Progress = quiet
) -> Calibrations:
    """Calibrate every method on the head ``settings`` (seeded by ``config.seed``)."""
    start = time.perf_counter()
    stereo_calibration, views = zhang_stereo(settings, config)
    renders = views.renders
    progress(
        f"  stereo: {views.views} views, RMS {stereo_calibration.stereo_rms_px:.3f} px, "
        f"focal errors {', '.join(f'{100 * e:+.2f} %' for e in stereo_calibration.cam1.focal_rel_errors)}"
    )
    principal = zoom_fixed_points(settings, config)
    renders += principal.renders
    progress(
        "  zoom fixed point: error "
        + ", ".join(f"({e[0]:+.2f}, {e[1]:+.2f})" for e in principal.errors_px)
        + " px"
    )
    positions = calibration_positions(start_views(settings), settings, config)
    active = SecV(*calibration_run(settings, positions))
    progress(
        f"  Sec. V, image centre: {active.report.fixated} samples, alpha_e error "
        + ", ".join(f"{1e3 * e:+.3f}" for e in active.alpha_e_error_rad)
        + " mrad"
    )
    (u1, _), (u2, _) = principal.principal_px
    fixed = SecV(*calibration_run(settings, positions, goal_columns_px=(u1, u2)))
    renders += active.report.renders.total + fixed.report.renders.total
    progress(
        f"  Sec. V, fixed point: {fixed.report.fixated} samples, alpha_e error "
        + ", ".join(f"{1e3 * e:+.3f}" for e in fixed.alpha_e_error_rad)
        + " mrad"
    )
    return Calibrations(
        settings=settings,
        stereo=stereo_calibration,
        active=active,
        principal=principal,
        fixed_point=fixed,
        seconds=time.perf_counter() - start,
        renders=renders,
    )


class CalibrationCache:
    """Calibrations by head, so that a head is calibrated once per study."""

    def __init__(self, config: StudyConfig, progress: Progress = quiet) -> None:
        self.config = config
        self.progress = progress
        self._cache: dict[HeadSettings, Calibrations] = {}

    def add(self, calibrations: Calibrations) -> None:
        """Use ``calibrations`` for their head from now on."""
        self._cache[calibrations.settings] = calibrations

    def __call__(self, settings: HeadSettings, label: str) -> Calibrations:
        if settings not in self._cache:
            self.progress(f"calibrating every method on {label}")
            self._cache[settings] = calibrate_methods(settings, self.config, self.progress)
        return self._cache[settings]

    @property
    def calibrations(self) -> list[Calibrations]:
        return list(self._cache.values())
