"""Calibrated stereo against the active method, after calibration and after the cameras change.

Pure orchestration over :mod:`headsim.stereo.zhang`, :mod:`headsim.active.procedures` and
:mod:`headsim.active.principal`; every error is estimate minus the simulator's truth
in the head frame H, and "% of depth" divides by the true z_h.

**Methods** (:data:`METHODS`), each with its own calibration
(:func:`calibrate_methods`):

- ``stereo``: Zhang calibration on chessboard views at eye angle 0, then
  triangulation at eye angle 0 (the paper's Sec. VI-B baseline).
- ``active_v_known``: Model 2 with the Sec. V initial directions, the servo on
  the image centre's column and the principal point's v from the Zhang
  calibration (the paper's Table V condition).
- ``active_centre``: the same with the image centre's row (Table VI: no
  intrinsic parameter at all).
- ``active_extended``: the same with v0 and kx/ky fitted from the Sec. V
  samples themselves (``calibrate_head``'s extended calibration).
- ``active_fixed_point``: beyond the paper: the principal point found as the
  fixed point of a zoom (images only, :mod:`headsim.active.principal`), the servo on
  its column, and the initial directions, v0 and kx/ky calibrated as for
  ``active_extended`` with that servo.
- ``active_refound``: ``active_fixed_point`` that finds the fixed point again
  (one more zoom, images only) on the head it measures, keeping its initial
  directions and kx/ky: on the principal point's column the initial
  direction is the mount yaw, which no intrinsic change moves.

**Conditions.**  A :class:`Condition` is a head to measure on, the targets to
measure, and whether the methods keep the calibration made on the study's
base head (``"kept"``: the cameras changed after calibration, e.g. a zoom) or
are calibrated again on this head (``"redone"``).  :func:`run_conditions`
measures every method on every target of every condition.

**Experiments.**  :func:`compare_experiment`: the six target positions of
Tables V and VI, then the same targets after a zoom (1.5x, 0.7x), a
principal-point shift and a distortion change with the calibrations kept, on
the paper's cameras and on the paper's cameras with centred principal points.
:data:`SWEEPS`: error against depth, focal length, principal-point shift,
k1, image noise and encoder resolution.  :func:`write_experiment` writes
``<name>.csv`` (a row per condition and method), ``<name>_targets.csv`` (a
row per target), ``<name>.json`` and ``<name>.png`` beside ``results.json``,
which indexes every experiment written to the directory.  The realistic
head's error budget (``--experiment budget``) is :mod:`headsim.studies.error_budget`.

    python -m headsim.studies.study --experiment compare --out out/study
    python -m headsim.studies.study --sweep depth --out out/study [--fast]
    python -m headsim.studies.study --experiment budget --out out/study [--fast]
    python -m headsim.studies.study --all --out out/study
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from headsim.active.calibration import CalibrationRun, calibrate_head
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, body_target
from headsim.active.model2 import measure_model2
from headsim.active.placement import calibration_layout
from headsim.active.principal import (
    PROBE_ZOOM,
    PrincipalPointRun,
    principal_points_by_zoom,
    view_scale,
    zoomed,
)
from headsim.errors import BadInput, JobFailed
from headsim.run.progress import Status
from headsim.run.results import to_jsonable, write_csv_atomic, write_json_atomic
from headsim.sim import names
from headsim.sim.optics import centre_ray_yaw
from headsim.sim.settings import HeadSettings, preset
from headsim.sim.simulator import HeadSim
from headsim.stereo import zhang as stereo
from headsim.vision.detect import find_marker

METHODS = (
    "stereo",
    "active_v_known",
    "active_centre",
    "active_extended",
    "active_fixed_point",
    "active_refound",
)
#: The methods of the sweeps: re-finding the fixed point matters only where
#: the principal point moves (the comparison and the principal-point sweep).
SWEEP_METHODS = METHODS[:5]
#: How each method is named in tables and plots.
METHOD_LABELS = {
    "stereo": "calibrated stereo",
    "active_v_known": "active, v known (Table V)",
    "active_centre": "active, image centre (Table VI)",
    "active_extended": "active, extended calibration",
    "active_fixed_point": "active, zoom fixed point",
    "active_refound": "active, zoom fixed point found again",
}
TARGET = body_target(names.MARKERS[0], partial(find_marker, colour="red"))
BALL = body_target(names.CALIBRATION_BALL, partial(find_marker, colour="yellow"))

#: The six target positions of the Tables V/VI comparison, in H, m: 0.4-1.2 m
#: deep, spread sideways and vertically around x_h/z_h = 0.05, where the paper
#: preset's eyes (both turned towards +x by their mounts) share their views:
#: all are seen by both cameras at eye angle 0 and in the active method's step
#: images, also after a 1.5x or 0.7x zoom.
TABLE_TARGETS_HEAD = (
    (0.030, 0.010, 0.40),
    (0.005, 0.025, 0.55),
    (0.075, -0.035, 0.70),
    (0.000, -0.030, 0.85),
    (0.095, 0.045, 1.00),
    (0.010, 0.030, 1.20),
)

Progress = Callable[[str], None]


def quiet(_: str) -> None:
    """A progress callback that says nothing."""


# -- configuration ---------------------------------------------------------------


@dataclass(frozen=True)
class StudyConfig:
    """How much work each calibration and sweep point does.

    ``board_poses``: chessboard poses for the stereo calibration;
    ``calibration_targets``: Sec. V targets per active calibration;
    ``principal_poses``: chessboard poses per zoom fixed point;
    ``targets_per_depth``: targets at each depth of the depth sweep;
    ``table_targets``: how many of :data:`TABLE_TARGETS_HEAD` the other
    sweeps measure; ``fast``: the sweeps' short value lists.
    """

    preset: str = "paper"
    seed: int = 0
    board_poses: int = 20
    calibration_targets: int = 60
    principal_poses: int = 4
    targets_per_depth: int = 4
    table_targets: int = 6
    fast: bool = False

    @classmethod
    def quick(cls, **overrides: Any) -> StudyConfig:
        """The smallest study that still calibrates every method (tests, smoke runs)."""
        values = {
            "board_poses": 8,
            "calibration_targets": 16,
            "principal_poses": 1,
            "targets_per_depth": 2,
            "table_targets": 3,
            "fast": True,
        }
        values.update(overrides)
        return cls(**values)


# -- calibrating every method ----------------------------------------------------


@dataclass(frozen=True)
class Calibrations:
    """Every method's calibration on one head.

    ``stereo``: the Zhang calibration; ``active``: Sec. V with the servo on
    the image centre (with the extended vertical fit); ``principal``: the
    zoom fixed points; ``fixed_point``: Sec. V with the servo on the fixed
    points' columns.  ``seconds``/``renders``: what calibrating cost.
    """

    settings: HeadSettings
    stereo: stereo.StereoCalibration
    active: CalibrationRun
    principal: PrincipalPointRun
    fixed_point: CalibrationRun
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
                "samples": active.samples,
                "renders": active.renders,
                "alpha_e_rad": active.fit.alpha_e,
                "truth_alpha_e_rad": active.truth_alpha_e,
                "alpha_e_error_mrad": active.alpha_e_error * 1e3,
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
                "samples": fixed.samples,
                "renders": fixed.renders,
                "goal_columns_px": self.goal_columns(),
                "alpha_e_rad": fixed.fit.alpha_e,
                # On the principal point's column the offsets are the mount yaws.
                "truth_alpha_e_rad": fixed.truth_alpha_e,
                "mount_yaw_rad": mount_yaws,
                "alpha_e_error_mrad": fixed.alpha_e_error * 1e3,
                "v0_px": fixed.knowledge.v0,
                "kx_over_ky": fixed.knowledge.kx_over_ky,
            },
        }


def zhang_stereo(
    settings: HeadSettings, config: StudyConfig
) -> tuple[stereo.StereoCalibration, stereo.ChessboardViews]:
    """Zhang's calibration of ``settings``' pair from ``config.board_poses`` chessboard
    poses (seeded by ``config.seed``), and the views it used."""
    scale = view_scale(settings)
    with HeadSim("chessboard", settings) as sim:
        views = stereo.chessboard_views(
            sim,
            config.board_poses,
            np.random.default_rng(config.seed),
            distance_range_m=(0.4 * scale, 1.0 * scale),
        )
        return stereo.calibrate_stereo(sim, views), views


def zoom_fixed_points(settings: HeadSettings, config: StudyConfig) -> PrincipalPointRun:
    """The zoom fixed points of ``settings``' cameras, seeded by ``config.seed``."""
    return principal_points_by_zoom(
        settings, PROBE_ZOOM, np.random.default_rng(config.seed + 1), config.principal_poses
    )


def calibration_positions(sim: HeadSim, settings: HeadSettings, config: StudyConfig) -> np.ndarray:
    """The Sec. V ball positions of every method (seeded by ``config.seed``)."""
    scale = view_scale(settings)
    return calibration_layout(
        sim,
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
        f"  stereo: {views.count} views, RMS {stereo_calibration.stereo_rms_px:.3f} px, "
        f"focal errors {', '.join(f'{100 * e:+.2f} %' for e in stereo_calibration.cam1.focal_rel_errors)}"
    )
    principal = zoom_fixed_points(settings, config)
    renders += principal.renders
    progress(
        "  zoom fixed point: error "
        + ", ".join(f"({e[0]:+.2f}, {e[1]:+.2f})" for e in principal.errors_px)
        + " px"
    )
    with HeadSim("default", settings) as sim:
        positions = calibration_positions(sim, settings, config)
        active = calibrate_head(sim, EyeServo(sim), BALL, names.CALIBRATION_BALL, positions)
        progress(
            f"  Sec. V, image centre: {active.samples} samples, alpha_e error "
            + ", ".join(f"{1e3 * e:+.3f}" for e in active.alpha_e_error)
            + " mrad"
        )
        (u1, _), (u2, _) = principal.principal_px
        fixed = calibrate_head(
            sim,
            EyeServo(sim),
            BALL,
            names.CALIBRATION_BALL,
            positions,
            knowledge=HeadKnowledge(u0=(u1, u2)),
        )
        renders += active.renders + fixed.renders
    progress(
        f"  Sec. V, fixed point: {fixed.samples} samples, alpha_e error "
        + ", ".join(f"{1e3 * e:+.3f}" for e in fixed.alpha_e_error)
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


# -- measuring -------------------------------------------------------------------


@dataclass(frozen=True)
class TargetError:
    """One target measured by one method: truth and estimate in H, m.

    ``status``: "ok" or why the method failed (estimate NaN then).
    """

    method: str
    index: int
    truth_head_m: np.ndarray
    estimate_head_m: np.ndarray
    status: str
    renders: int

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def error_m(self) -> np.ndarray:
        """Estimate minus truth in H, m."""
        return self.estimate_head_m - self.truth_head_m

    @property
    def error_pct_depth(self) -> float:
        """3-D error as a percentage of the true depth z_h."""
        return float(100 * np.linalg.norm(self.error_m) / self.truth_head_m[2])


def _place(sim: HeadSim, body: str, p_head: np.ndarray) -> None:
    sim.set_body_pose(body, sim.transform_points(p_head, "head", "world")[0])


def measure_methods(
    settings: HeadSettings,
    calibrations: Calibrations,
    targets_head: np.ndarray,
    methods: Sequence[str] = SWEEP_METHODS,
    config: StudyConfig | None = None,
) -> list[TargetError]:
    """Measure the red marker at each of ``targets_head`` (N, 3) m with each method.

    The head is ``settings`` (which may differ from the one calibrated);
    every method uses ``calibrations`` as they are, except that
    ``active_refound`` first finds the zoom fixed points on ``settings``
    (``config``'s seed and poses).
    """
    config = config or StudyConfig()
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown methods {unknown}; allowed: {', '.join(METHODS)}")
    out: list[TargetError] = []
    with HeadSim("default", settings) as sim:
        servo = EyeServo(sim)
        refound = None
        if "active_refound" in methods:
            refound = principal_points_by_zoom(
                settings, PROBE_ZOOM, np.random.default_rng(config.seed + 1), config.principal_poses
            )
        for index, p_head in enumerate(np.atleast_2d(np.asarray(targets_head, dtype=float))):
            _place(sim, TARGET.name, p_head)
            truth = sim.position(TARGET.name, "head")
            for method in methods:
                start = sim.render_count
                if method == "stereo":
                    try:
                        m = stereo.measure_point_stereo(sim, calibrations.stereo, TARGET.name)
                        estimate, status = m.p_head, "ok"
                    except stereo.StereoError as error:
                        estimate, status = np.full(3, np.nan), str(error)
                else:
                    m2 = measure_model2(sim, servo, TARGET, calibrations.knowledge(method, refound))
                    estimate, status = m2.estimate_head_m, m2.status_text
                out.append(
                    TargetError(method, index, truth, estimate, status, sim.render_count - start)
                )
                sim.move(eye=0.0)
    return out


@dataclass(frozen=True)
class Summary:
    """One method's errors over a condition's targets (ok ones; ``failed`` counts the others).

    RMS over targets of: the 3-D error (mm), the 3-D error / depth (%), the
    error in x and z only / depth (%), the error in y / depth (%); the worst
    3-D error / depth (%).
    """

    method: str
    ok: int
    failed: int
    rms_mm: float
    rms_pct_depth: float
    rms_xz_pct_depth: float
    rms_y_pct_depth: float
    max_pct_depth: float


def summarise(errors: Iterable[TargetError], method: str) -> Summary:
    """:class:`Summary` of ``method``'s entries in ``errors``."""
    rows = [e for e in errors if e.method == method]
    good = [e for e in rows if e.ok]
    if not good:
        nan = math.nan
        return Summary(method, 0, len(rows), nan, nan, nan, nan, nan)
    err = np.array([e.error_m for e in good])
    depth = np.array([e.truth_head_m[2] for e in good])
    rel = err / depth[:, None]
    return Summary(
        method=method,
        ok=len(good),
        failed=len(rows) - len(good),
        rms_mm=float(1e3 * np.sqrt(np.mean(np.sum(err**2, axis=1)))),
        rms_pct_depth=float(100 * np.sqrt(np.mean(np.sum(rel**2, axis=1)))),
        rms_xz_pct_depth=float(100 * np.sqrt(np.mean(rel[:, 0] ** 2 + rel[:, 2] ** 2))),
        rms_y_pct_depth=float(100 * np.sqrt(np.mean(rel[:, 1] ** 2))),
        max_pct_depth=float(100 * np.max(np.linalg.norm(rel, axis=1))),
    )


# -- conditions ------------------------------------------------------------------


@dataclass(frozen=True)
class Condition:
    """A head to measure on and the targets to measure.

    ``group``: which curve or panel it belongs to (e.g. the base head's name);
    ``label``: for people; ``value``: the x of a sweep; ``calibration``:
    "kept" (the methods use the calibrations made on the base head) or
    "redone" (calibrated on ``head``).
    """

    group: str
    label: str
    value: float
    head: HeadSettings
    calibration: str
    targets_head: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        if self.calibration not in ("kept", "redone"):
            raise ValueError(f"calibration must be 'kept' or 'redone', got {self.calibration!r}")


@dataclass(frozen=True)
class ConditionResult:
    condition: Condition
    errors: tuple[TargetError, ...]
    summaries: tuple[Summary, ...]
    seconds: float

    def summary(self, method: str) -> Summary:
        return next(s for s in self.summaries if s.method == method)


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


@dataclass(frozen=True)
class ConditionJob:
    """One condition to measure, as a job for :func:`headsim.studies.sweep.map_jobs`.

    ``calibrations``: made by the parent for "kept" conditions (shared by
    many); None for "redone" ones, which the worker calibrates itself.
    """

    index: int
    id: str
    condition: Condition
    calibrations: Calibrations | None
    methods: tuple[str, ...]
    config: StudyConfig


def measure_condition(job: ConditionJob, marker_dir: str | None = None) -> dict[str, Any]:
    """Run one condition (in a worker process); the record carries its ConditionResult."""
    start = time.perf_counter()
    calibrations = job.calibrations or calibrate_methods(job.condition.head, job.config)
    errors = measure_methods(
        job.condition.head, calibrations, job.condition.targets_head, job.methods, job.config
    )
    summaries = tuple(summarise(errors, m) for m in job.methods)
    result = ConditionResult(job.condition, tuple(errors), summaries, time.perf_counter() - start)
    return {
        "id": job.id,
        "index": job.index,
        "status": "ok",
        "result": result,
        "calibrations": None if job.calibrations else calibrations,
    }


def run_conditions(
    base: dict[str, HeadSettings],
    conditions: Sequence[Condition],
    cache: CalibrationCache,
    methods: Sequence[str] = SWEEP_METHODS,
    progress: Progress = quiet,
    workers: int = 1,
    scheduler: str | None = None,
) -> list[ConditionResult]:
    """Measure every condition; ``base`` maps each condition's ``group`` to the head calibrated for "kept".

    With ``workers`` > 1 or a Dask ``scheduler`` the conditions run as jobs of
    :func:`headsim.studies.sweep.map_jobs` (the "kept" calibrations are made here once
    and shipped with them); otherwise one after the other in this process.
    """
    methods = tuple(methods)
    jobs = []
    for number, condition in enumerate(conditions):
        calibrations = None
        if condition.calibration == "kept":
            calibrations = cache(base[condition.group], f"{condition.group} (base head)")
        elif workers == 1 and scheduler is None:
            calibrations = cache(condition.head, f"{condition.group}: {condition.label}")
        job_id = f"{number}-{condition.group}-{condition.label}-{condition.calibration}"
        jobs.append(ConditionJob(number, job_id, condition, calibrations, methods, cache.config))
    done = 0

    def report(record: dict[str, Any]) -> None:
        nonlocal done
        done += 1
        if record.get("status") != "ok":
            progress(f"[{done}/{len(jobs)}] job {record['id']} failed: {record.get('error')}")
            return
        result = record["result"]
        c = result.condition
        figures = ", ".join(
            f"{m.removeprefix('active_')} {s.rms_pct_depth:.3f}"
            + (f" ({s.failed} failed)" if s.failed else "")
            for m, s in zip(methods, result.summaries, strict=True)
        )
        progress(
            f"[{done}/{len(jobs)}] {c.group}: {c.label} ({c.calibration}): "
            f"RMS % of depth: {figures}  [{result.seconds:.1f} s]"
        )

    if workers == 1 and scheduler is None:
        records = []
        for job in jobs:
            records.append(measure_condition(job))
            report(records[-1])
    else:
        from headsim.studies.sweep import map_jobs

        records = map_jobs(
            measure_condition, jobs, workers=workers, scheduler=scheduler, on_record=report
        )
    failed = [r for r in records if r.get("status") != "ok"]
    if failed:
        raise JobFailed(f"{len(failed)} condition(s) failed: {failed[0].get('error')}")
    for record in records:
        if record.get("calibrations") is not None:
            cache.add(record["calibrations"])
    return [record["result"] for record in records]


# -- heads and changes -------------------------------------------------------------


def centred(settings: HeadSettings) -> HeadSettings:
    """The same head with both principal points at the image centre."""
    return replace(settings, cameras=tuple(replace(c, cx=None, cy=None) for c in settings.cameras))


def principal_shifted(settings: HeadSettings, shift_px: float) -> HeadSettings:
    """Principal points moved ``shift_px``: Ca1's u by +shift, Ca2's u by -shift, both v by +shift.

    Mirror images in u, so that the image centre's rays of both eyes turn
    the same way relative to their inward directions and their effect on
    the depth adds up instead of cancelling.
    """
    cams = []
    for sign, cam in zip((1.0, -1.0), settings.cameras, strict=True):
        cx, cy = cam.principal
        cams.append(replace(cam, cx=cx + sign * shift_px, cy=cy + shift_px))
    return replace(settings, cameras=(cams[0], cams[1]))


def k1_changed(settings: HeadSettings, change: float) -> HeadSettings:
    """Both cameras' k1 changed by ``change`` (positive: less barrel distortion)."""
    return replace(settings, cameras=tuple(replace(c, k1=c.k1 + change) for c in settings.cameras))


def with_noise(settings: HeadSettings, noise_std: float) -> HeadSettings:
    """Both cameras with Gaussian image noise of ``noise_std`` grey levels."""
    return replace(
        settings, cameras=tuple(replace(c, noise_std=noise_std) for c in settings.cameras)
    )


def with_encoder(settings: HeadSettings, steps_per_turn: float) -> HeadSettings:
    """The eye encoder with ``steps_per_turn`` steps per revolution."""
    return replace(settings, encoder_resolution_rad=2 * math.pi / steps_per_turn)


#: The changes after calibration of the comparison: label -> (x value, change).
CHANGES: dict[str, tuple[float, Callable[[HeadSettings], HeadSettings]]] = {
    "zoom 1.5x": (1.5, lambda s: zoomed(s, 1.5)),
    "zoom 0.7x": (0.7, lambda s: zoomed(s, 0.7)),
    "principal point moved 5 px": (5.0, lambda s: principal_shifted(s, 5.0)),
    "k1 + 0.1": (0.1, lambda s: k1_changed(s, 0.1)),
}


def image_centre_directions(settings: HeadSettings) -> tuple[float, float]:
    """Each eye's true effective initial direction, rad: mount yaw plus the image centre's ray.

    What the Sec. V calibration with the servo on the image centre finds
    (``HeadSim.effective_initial_direction`` without mount pitch or roll);
    for explaining the errors, never given to a method.
    """
    yaws = [
        c.mount_yaw_rad + s * centre_ray_yaw(c)
        for s, c in zip((1, -1), settings.cameras, strict=True)
    ]
    return (yaws[0], yaws[1])


def table_targets(count: int = len(TABLE_TARGETS_HEAD)) -> np.ndarray:
    """The first ``count`` of :data:`TABLE_TARGETS_HEAD` (count, 3), m."""
    return np.array(TABLE_TARGETS_HEAD[:count], dtype=float)


def depth_targets(
    settings: HeadSettings,
    depth_m: float,
    count: int,
    rng: np.random.Generator,
    lateral: float = 0.06,
    vertical: float = 0.05,
) -> np.ndarray:
    """``count`` targets (count, 3) in H at depth ``depth_m``, m.

    x/z is uniform within ``lateral`` of the direction both eyes look along
    at eye angle 0 (the mean of their mount yaws, read from the settings to
    place targets only), y/z within ``vertical`` of 0.
    """
    look = math.tan((settings.cameras[0].mount_yaw_rad - settings.cameras[1].mount_yaw_rad) / 2)
    return np.column_stack(
        [
            (look + rng.uniform(-lateral, lateral, count)) * depth_m,
            rng.uniform(-vertical, vertical, count) * depth_m,
            np.full(count, depth_m),
        ]
    )


# -- experiments -------------------------------------------------------------------


@dataclass(frozen=True)
class Experiment:
    """A named set of conditions and how to plot them.

    ``kind``: "compare" (bars per condition) or "sweep" (curves against
    ``value``); ``parameter``: the sweep's x axis label; ``methods``: those
    measured; ``log_x``: plot x on a log scale.
    """

    name: str
    title: str
    kind: str
    parameter: str
    base: dict[str, HeadSettings]
    conditions: tuple[Condition, ...]
    methods: tuple[str, ...] = SWEEP_METHODS
    log_x: bool = False


def compare_experiment(config: StudyConfig) -> Experiment:
    """Tables V/VI and the changes after calibration, on the preset and on it with centred principal points."""
    head = preset(config.preset, seed=config.seed)
    targets = table_targets(config.table_targets)
    base = {config.preset: head, f"{config.preset} with centred principal points": centred(head)}
    changes = CHANGES if not config.fast else dict(list(CHANGES.items())[:1])
    conditions = []
    for group, settings in base.items():
        conditions.append(Condition(group, "as calibrated", 0.0, settings, "kept", targets))
        for label, (value, change) in changes.items():
            conditions.append(Condition(group, label, value, change(settings), "kept", targets))
    return Experiment(
        name="compare",
        title="Tables V/VI, then the cameras change after calibration",
        kind="compare",
        parameter="condition",
        base=base,
        conditions=tuple(conditions),
        methods=METHODS,
    )


@dataclass(frozen=True)
class Sweep:
    """One sweep: values, how each changes the head, and the calibration modes.

    ``change(head, value)``: the head at that value; ``modes``: "kept"
    (calibrated on the preset, changed after) and/or "redone".
    """

    name: str
    parameter: str
    values: tuple[float, ...]
    fast_values: tuple[float, ...]
    change: Callable[[HeadSettings, float], HeadSettings]
    modes: tuple[str, ...]
    log_x: bool = False


SWEEPS: dict[str, Sweep] = {
    "depth": Sweep(
        "depth",
        "target depth z_h, m",
        (0.3, 0.45, 0.6, 0.8, 1.0, 1.25, 1.5, 2.0),
        (0.4, 1.5),
        lambda head, _: head,
        ("kept",),
    ),
    "focal": Sweep(
        "focal",
        "focal length / calibrated focal length",
        (0.7, 0.85, 1.0, 1.2, 1.5),
        (1.0, 1.5),
        zoomed,
        ("kept", "redone"),
    ),
    "principal": Sweep(
        "principal",
        "principal point shift, px (Ca1 u +, Ca2 u -, both v +)",
        (-10.0, -5.0, -2.0, 0.0, 2.0, 5.0, 10.0),
        (0.0, 5.0),
        principal_shifted,
        ("kept", "redone"),
    ),
    "k1": Sweep(
        "k1",
        "change of k1 (both cameras)",
        (-0.1, -0.05, 0.0, 0.05, 0.1, 0.2),
        (0.0, 0.1),
        k1_changed,
        ("kept", "redone"),
    ),
    "noise": Sweep(
        "noise",
        "image noise, grey levels (std)",
        (0.0, 2.0, 4.0, 8.0),
        (0.0, 4.0),
        with_noise,
        ("redone",),
    ),
    "encoder": Sweep(
        "encoder",
        "eye encoder, steps per turn",
        (3200.0, 6400.0, 12800.0, 25600.0, 102400.0),
        (6400.0, 25600.0),
        with_encoder,
        ("redone",),
        log_x=True,
    ),
}


def sweep_experiment(name: str, config: StudyConfig) -> Experiment:
    """The conditions of sweep ``name`` (:data:`SWEEPS`) on the preset's head."""
    if name not in SWEEPS:
        raise ValueError(f"unknown sweep {name!r}; allowed: {', '.join(SWEEPS)}")
    sweep = SWEEPS[name]
    head = preset(config.preset, seed=config.seed)
    values = sweep.fast_values if config.fast else sweep.values
    rng = np.random.default_rng(config.seed + 10)
    conditions = []
    for value in values:
        if name == "depth":
            targets = depth_targets(head, value, config.targets_per_depth, rng)
        else:
            targets = table_targets(config.table_targets)
        changed = sweep.change(head, value)
        for mode in sweep.modes:
            conditions.append(Condition(config.preset, f"{value:g}", value, changed, mode, targets))
    return Experiment(
        name=name,
        title=f"error against {sweep.parameter}",
        kind="sweep",
        parameter=sweep.parameter,
        base={config.preset: head},
        conditions=tuple(conditions),
        methods=METHODS if name == "principal" else SWEEP_METHODS,
        log_x=sweep.log_x,
    )


@dataclass(frozen=True)
class ExperimentResult:
    experiment: Experiment
    config: StudyConfig
    results: tuple[ConditionResult, ...]
    calibrations: tuple[Calibrations, ...]
    seconds: float

    def summary(self, group: str, label: str, calibration: str, method: str) -> Summary:
        """The summary of one method in one condition."""
        for r in self.results:
            c = r.condition
            if (c.group, c.label, c.calibration) == (group, label, calibration):
                return r.summary(method)
        raise KeyError((group, label, calibration))


def run_experiment(
    experiment: Experiment,
    config: StudyConfig,
    methods: Sequence[str] | None = None,
    progress: Progress = quiet,
    cache: CalibrationCache | None = None,
    workers: int = 1,
    scheduler: str | None = None,
) -> ExperimentResult:
    """Run every condition of ``experiment`` with ``methods`` (default: the experiment's).

    ``workers``/``scheduler``: as :func:`run_conditions`.
    """
    methods = experiment.methods if methods is None else tuple(methods)
    start = time.perf_counter()
    progress(f"== {experiment.name}: {experiment.title} ({len(experiment.conditions)} conditions)")
    cache = cache or CalibrationCache(config, progress)
    results = run_conditions(
        experiment.base, experiment.conditions, cache, methods, progress, workers, scheduler
    )
    used = {
        (experiment.base[c.group] if c.calibration == "kept" else c.head)
        for c in experiment.conditions
    }
    calibrations = tuple(c for c in cache.calibrations if c.settings in used)
    return ExperimentResult(
        experiment, config, tuple(results), calibrations, time.perf_counter() - start
    )


# -- figures for the done-when ---------------------------------------------


def compare_figures(result: ExperimentResult) -> dict[str, Any]:
    """The done-when ratios of the comparison (RMS of the 3-D error, mm)."""
    exp = result.experiment
    groups = list(exp.base)
    paper = groups[0]
    figures: dict[str, Any] = {}

    def rms(group: str, label: str, method: str) -> float:
        return result.summary(group, label, "kept", method).rms_mm

    methods = [s.method for s in result.results[0].summaries]
    stereo_rms = rms(paper, "as calibrated", "stereo")
    figures["tables_v_vi"] = {
        "stereo_rms_mm": stereo_rms,
        **{f"{m}_over_stereo": rms(paper, "as calibrated", m) / stereo_rms for m in methods[1:]},
    }
    # How far each change turned the image centre's rays (the plain method's offsets).
    turns = {}
    for c in exp.conditions:
        before, after = (image_centre_directions(h) for h in (exp.base[c.group], c.head))
        turns[f"{c.group}: {c.label}"] = [1e3 * (a - b) for a, b in zip(after, before, strict=True)]
    figures["image_centre_ray_turn_mrad"] = turns
    labels = {c.label for c in exp.conditions}
    if "zoom 1.5x" in labels:
        # The second group (if any) is the paper's head with centred principal points.
        keys = {paper: "zoom_1_5_paper", **{g: "zoom_1_5_centred" for g in groups[1:2]}}
        for group, key in keys.items():
            figures[key] = {
                f"{m}_after_over_before": rms(group, "zoom 1.5x", m)
                / rms(group, "as calibrated", m)
                for m in methods
            }
    return figures


# -- writing -------------------------------------------------------------------------


def summary_rows(result: ExperimentResult) -> list[dict[str, Any]]:
    """A row per condition and method."""
    rows = []
    for r in result.results:
        c = r.condition
        for s in r.summaries:
            rows.append(
                {
                    "experiment": result.experiment.name,
                    "group": c.group,
                    "condition": c.label,
                    "value": float(c.value),
                    "calibration": c.calibration,
                    "method": s.method,
                    "ok": s.ok,
                    "failed": s.failed,
                    "rms_mm": s.rms_mm,
                    "rms_pct_depth": s.rms_pct_depth,
                    "rms_xz_pct_depth": s.rms_xz_pct_depth,
                    "rms_y_pct_depth": s.rms_y_pct_depth,
                    "max_pct_depth": s.max_pct_depth,
                }
            )
    return rows


def target_rows(result: ExperimentResult) -> list[dict[str, Any]]:
    """A row per condition, method and target."""
    rows = []
    for r in result.results:
        c = r.condition
        for e in r.errors:
            t, est, err = e.truth_head_m, e.estimate_head_m, e.error_m
            rows.append(
                {
                    "experiment": result.experiment.name,
                    "group": c.group,
                    "condition": c.label,
                    "value": float(c.value),
                    "calibration": c.calibration,
                    "method": e.method,
                    "target": e.index,
                    "status": e.status,
                    "renders": e.renders,
                    "true_x_m": float(t[0]),
                    "true_y_m": float(t[1]),
                    "true_z_m": float(t[2]),
                    "estimate_x_m": float(est[0]),
                    "estimate_y_m": float(est[1]),
                    "estimate_z_m": float(est[2]),
                    "error_x_mm": float(1e3 * err[0]),
                    "error_y_mm": float(1e3 * err[1]),
                    "error_z_mm": float(1e3 * err[2]),
                    "error_mm": float(1e3 * np.linalg.norm(err)),
                    "error_pct_depth": e.error_pct_depth,
                }
            )
    return rows


def write_experiment(
    result: ExperimentResult, out_dir: str | Path, figure: bool = True
) -> dict[str, Path]:
    """Write ``<name>.csv``, ``<name>_targets.csv``, ``<name>.json``, ``<name>.png`` and update
    ``results.json``; ``figure`` False: not the PNG (its caller draws it with
    ``headsim.studies.plots.plot_experiment``, e.g. in a process that has matplotlib loaded)."""
    out = Path(out_dir)
    name = result.experiment.name
    summaries = summary_rows(result)
    payload = {
        "experiment": name,
        "title": result.experiment.title,
        "parameter": result.experiment.parameter,
        "config": result.config,
        "seconds": result.seconds,
        "methods": METHOD_LABELS,
        "summary": summaries,
        "calibrations": [
            {"head": _head_description(c.settings), **c.report()} for c in result.calibrations
        ],
        "targets": target_rows(result),
    }
    if result.experiment.kind == "compare":
        payload["figures"] = compare_figures(result)
    files = {
        "csv": write_csv_atomic(out / f"{name}.csv", summaries),
        "targets_csv": write_csv_atomic(out / f"{name}_targets.csv", payload["targets"]),
        "json": write_json_atomic(out / f"{name}.json", payload),
        "png": out / f"{name}.png",
    }
    if figure:
        from headsim.studies import plots  # matplotlib loads only when figures are written

        plots.plot_experiment(result, files["png"])
    index_path = out / "results.json"
    index: dict[str, Any] = {}
    if index_path.exists():
        try:
            index = json.loads(index_path.read_text())
        except json.JSONDecodeError:
            index = {}
    index.setdefault("experiments", {})[name] = {
        "title": result.experiment.title,
        "seconds": result.seconds,
        "files": {k: p.name for k, p in files.items()},
        **({"figures": payload["figures"]} if "figures" in payload else {}),
    }
    write_json_atomic(index_path, to_jsonable(index))
    return files


def _head_description(settings: HeadSettings) -> dict[str, Any]:
    return {
        "cameras": [
            {
                "kx": c.kx,
                "ky": c.ky,
                "principal": c.principal,
                "k1": c.k1,
                "mount_yaw_rad": c.mount_yaw_rad,
                "noise_std": c.noise_std,
            }
            for c in settings.cameras
        ],
        "encoder_resolution_rad": settings.encoder_resolution_rad,
    }


def print_result(result: ExperimentResult) -> None:
    """The RMS 3-D error (% of depth) of every method in every condition, as a table on stdout."""
    exp = result.experiment
    methods = [s.method for s in result.results[0].summaries] if result.results else []
    print(f"\n== {exp.name}: {exp.title} ({result.seconds:.0f} s)")
    print("RMS 3-D error, % of depth (failed targets in brackets)")
    header = f"{'group':34s} {'condition':28s} {'calib':6s} " + " ".join(
        f"{m.removeprefix('active_'):>12s}" for m in methods
    )
    print(header)
    for r in result.results:
        c = r.condition
        cells = []
        for s in r.summaries:
            cell = f"{s.rms_pct_depth:.4f}" + (f"[{s.failed}]" if s.failed else "")
            cells.append(f"{cell:>12s}")
        print(f"{c.group:34s} {c.label:28s} {c.calibration:6s} " + " ".join(cells))
    if exp.kind == "compare":
        print(json.dumps(to_jsonable(compare_figures(result)), indent=2))


# -- command line ------------------------------------------------------------------------


def add_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """The study's options (shared by ``python -m headsim.studies.study`` and ``headsim study``)."""
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument(
        "--experiment",
        choices=["compare", "budget"],
        help="compare: the Tables V/VI comparison; budget: the realistic head's error budget "
        "(headsim.studies.error_budget; scenario realistic_field, whatever --preset)",
    )
    what.add_argument("--sweep", choices=sorted(SWEEPS), help="one sweep")
    what.add_argument(
        "--all", action="store_true", help="the comparison, every sweep and the error budget"
    )
    parser.add_argument("--out", required=True, help="output directory (created if missing)")
    parser.add_argument("--preset", default="paper", choices=["ideal", "paper"])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--fast", action="store_true", help="small calibrations and two values per sweep"
    )
    parser.add_argument(
        "--workers", type=int, default=1, metavar="N", help="run conditions on N local processes"
    )
    parser.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="run conditions on this Dask scheduler (pip install 'headsim[dask]')",
    )
    return parser


STUDY_DESCRIPTION = (
    "Calibrated stereo against the active method: the Tables V/VI comparison, changes of "
    "focal length, principal point and distortion after calibration, and sweeps (depth, focal, "
    "principal, k1, noise, encoder), and the realistic head's error budget; writes CSV, JSON "
    "and PNG to --out."
)


def build_parser() -> argparse.ArgumentParser:
    return add_arguments(
        argparse.ArgumentParser(
            prog="python -m headsim.studies.study", description=STUDY_DESCRIPTION
        )
    )


def main(argv: Sequence[str] | None = None) -> int:
    return run(build_parser().parse_args(argv))


def run(args: argparse.Namespace) -> int:
    """Run what ``args`` (see :func:`add_arguments`) asks for; 0 on success."""
    if args.workers < 1:
        raise BadInput(f"--workers must be >= 1, got {args.workers}")
    make = StudyConfig.quick if args.fast else StudyConfig
    config = make(preset=args.preset, seed=args.seed)
    progress: Progress = quiet if getattr(args, "quiet", False) else Status("headsim study")
    cache = CalibrationCache(config, progress)
    if args.experiment == "budget":
        return _budget(args, progress)
    if args.all:
        experiments = [compare_experiment(config)] + [
            sweep_experiment(name, config) for name in SWEEPS
        ]
    elif args.experiment:
        experiments = [compare_experiment(config)]
    else:
        experiments = [sweep_experiment(args.sweep, config)]
    for experiment in experiments:
        result = run_experiment(
            experiment,
            config,
            progress=progress,
            cache=cache,
            workers=args.workers,
            scheduler=args.scheduler,
        )
        files = write_experiment(result, args.out)
        progress(
            f"{experiment.name}: {result.seconds:.1f} s; wrote {', '.join(map(str, files.values()))}"
        )
        print_result(result)
    return _budget(args, progress) if args.all else 0


def _budget(args: argparse.Namespace, progress: Progress) -> int:
    """The realistic head's error budget (:mod:`headsim.studies.error_budget`); 0 on success."""
    from headsim.studies import error_budget

    start = time.perf_counter()
    rows = error_budget.run_budget(
        fast=args.fast,
        seed=args.seed,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=progress,
    )
    files = error_budget.write_budget(rows, args.out, args.fast)
    progress(
        f"budget: {time.perf_counter() - start:.1f} s; wrote {', '.join(map(str, files.values()))}"
    )
    print(files["md"].read_text(), end="")
    failed = [f"{r['condition']}: {r['failures']}" for r in rows if r["failures"]]
    for line in failed:
        progress(f"budget: failed: {line}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
