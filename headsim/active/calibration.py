"""Sec. V calibration in the simulator: fixate a target at known positions with
Model 2 and fit each eye's initial direction (and, extended, the vertical
references, kx/ky ratios and line-of-sight offsets), with the truth beside it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from headsim.active.events import CalibrationPosition, FixationStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.failure import Failure, FailureCause
from headsim.active.measurement import (
    HeadKnowledge,
    Target,
)
from headsim.active.model2 import Model2Config, measure_model2
from headsim.estimators.calibration import (
    Calibration,
    LineOfSightCalibration,
    calibrate_initial_directions,
    calibrate_lines_of_sight,
)
from headsim.estimators.vertical import VerticalCalibration, calibrate_vertical_reference
from headsim.head.servo_head import ServoHead
from headsim.sim.events import EventSink


class CalibrationError(ValueError):
    """The calibration failed; the message names the cause, ``outcomes`` has each position's."""

    def __init__(self, message: str, outcomes: Sequence[Failure | None]) -> None:
        super().__init__(message)
        self.outcomes = tuple(outcomes)


def _causes_text(outcomes: Sequence[Failure | None]) -> str:
    """'3 Ca2 at step 1: target lost, 1 Ca1 at step 1: target cut' (most common first)."""
    counts: dict[str, int] = {}
    for f in outcomes:
        if f is not None:
            key = f.message.split(" (")[0]
            counts[key] = counts.get(key, 0) + 1
    return ", ".join(f"{n} {k}" for k, n in sorted(counts.items(), key=lambda kv: -kv[1]))


@dataclass(frozen=True)
class CalibrationRun:
    """Sec. V calibration in the simulator, with the truth beside it.

    ``fit``: the estimator's result (offsets, standard errors, residuals).
    ``truth_alpha_e``: each eye's effective initial direction, rad (simulator).
    ``vertical``: the extended calibration per camera (v0, kx/ky), or None.
    ``lines``: the extended fit of each eye's initial direction and
    line-of-sight offset from the targets' measured positions, or None.
    ``outcomes``: per layout position, None (fixated) or why it was not.
    """

    fit: Calibration
    truth_alpha_e: tuple[float, float]
    samples: int
    renders: int
    depth_noise_m: float
    vertical: tuple[VerticalCalibration, VerticalCalibration] | None
    knowledge: HeadKnowledge
    lines: LineOfSightCalibration | None = None
    position_noise_m: float = 0.0
    outcomes: tuple[Failure | None, ...] = ()

    @property
    def alpha_e_error(self) -> np.ndarray:
        """Calibrated minus true effective initial directions, rad."""
        return np.asarray(self.fit.alpha_e) - np.asarray(self.truth_alpha_e)


def tape_measure(
    truth_head_m: np.ndarray,
    rng: np.random.Generator,
    *,
    position_noise_m: float = 0.0,
    depth_noise_m: float = 0.0,
) -> np.ndarray:
    """A target's position in H as the user measures it (a tape measure), m.

    The true position (3,) plus Gaussian error of ``position_noise_m`` on each
    coordinate and, on z_h only, of ``depth_noise_m`` besides (so z_h's error
    has the standard deviation ``hypot(position_noise_m, depth_noise_m)``).
    Drawn from ``rng`` in that order, each only when its noise is > 0.  The one
    place :func:`calibrate_head` draws the tape's errors.
    """
    measured = np.array(truth_head_m, dtype=float)
    if position_noise_m > 0:
        measured = measured + rng.normal(0.0, position_noise_m, 3)
    if depth_noise_m > 0:
        measured[2] += rng.normal(0.0, depth_noise_m)
    return measured


def calibrate_head(
    sim: ServoHead,
    servo: EyeServo,
    target: Target,
    body: str,
    positions_world: np.ndarray,
    *,
    depth_noise_m: float = 0.0,
    rng: np.random.Generator | None = None,
    extended: bool = True,
    knowledge: HeadKnowledge | None = None,
    position_noise_m: float = 0.0,
    lines_of_sight: bool = False,
    sink: EventSink | None = None,
) -> CalibrationRun:
    """Fixate ``target`` (moved with body ``body``) at each position and calibrate.

    The depth z_h handed to the estimator is the true one plus Gaussian noise of
    ``depth_noise_m`` (a tape measure).  With ``extended``, the same samples
    also give each camera's vertical reference and kx/ky ratio (beyond the
    paper: it needs the targets' full known positions, not only their depth).
    ``knowledge``: what the head already knows; its goal columns ``u0`` are
    the ones the servo fixates on (default: the image centres).
    ``position_noise_m``: Gaussian error of every coordinate a user measures
    of each target (x_h, y_h, z_h from the head's frame: a tape measure), m;
    the depth noise adds to it on z_h.  Every fit takes the measured values.
    With ``extended``, ``lines_of_sight`` and at least 3 targets, each eye's
    initial direction and line-of-sight offset are fitted jointly from the measured positions
    (:func:`calibrate_lines_of_sight`) and replace Sec. V's directions, unless
    the layout cannot separate them (``lines.separable`` False, with its message).
    ``sink``: where each position's fixation is reported ("calibration 1", ...; None:
    the simulator's sink).
    """
    sink = sim.sink if sink is None else sink
    base = replace(knowledge or HeadKnowledge(), alpha_e=(0.0, 0.0), los_offset_m=None)
    rng = rng or np.random.default_rng(0)
    start = sim.render_count
    parked = sim.truth.position(body)  # put the target back afterwards: it must not hide others
    alpha1, alpha2, depths, rows = [], [], [], []
    outcomes: list[Failure | None] = []
    # Plain first; near the midline the y images hold almost no x offset (NO_Y,
    # an estimator failure): then again, taking them at an intermediate eye angle
    # (the near-midline remedy).
    configs = (Model2Config(midline_px=0.0), Model2Config())
    for index, position in enumerate(np.atleast_2d(positions_world)):
        sink.emit(FixationStarted(f"calibration {index + 1}"))
        sim.truth.set_body_pose(body, position)
        for config in configs:
            m = measure_model2(sim, servo, target, base, config)
            if m.failure is None or m.failure.cause is not FailureCause.ESTIMATOR:
                break
        sink.emit(CalibrationPosition(index, position, m))
        outcomes.append(m.failure)
        if not m.ok:
            continue
        alpha1.append(m.details["alpha1_rad"])
        alpha2.append(m.details["alpha2_rad"])
        measured = tape_measure(
            m.truth_head_m, rng, position_noise_m=position_noise_m, depth_noise_m=depth_noise_m
        )
        depths.append(measured[2])
        rows.append((measured, m.details))
    sim.truth.set_body_pose(body, parked)
    baseline = base.head_belief(sim).baseline_m
    total = len(outcomes)
    if len(alpha1) < 2:
        raise CalibrationError(
            f"too few positions seen: {len(alpha1)} of {total} fixated (at least 2 needed) "
            f"because {_causes_text(outcomes)}",
            outcomes,
        )
    measured_rows = np.array([r[0] for r in rows])
    ratios = measured_rows[:, 0] / measured_rows[:, 2]
    # Without a depth error model the fit is unweighted and its standard errors
    # come from the scatter of its residuals (the angles' noise is not known a priori).
    z_sigma = math.hypot(depth_noise_m, position_noise_m)
    resolution = sim.settings.encoder_resolution_rad
    try:
        if np.ptp(alpha1) < resolution and np.ptp(alpha2) < resolution:
            # One place to the head (within an encoder step); the servo's averaged
            # sub-step angles differ by their scatter, so the fit alone may not tell.
            raise ValueError("their fixation angles lie within one encoder step of each other")
        fit = calibrate_initial_directions(
            np.array(alpha1),
            np.array(alpha2),
            np.array(depths),
            baseline,
            sigma_encoder=sim.settings.encoder_resolution_rad * 0.25 if z_sigma > 0 else None,
            sigma_depth=z_sigma if z_sigma > 0 else None,
        )
    except ValueError as err:
        raise CalibrationError(
            f"degenerate layout because the {len(alpha1)} fixated positions span depths "
            f"{measured_rows[:, 2].min():.3f}-{measured_rows[:, 2].max():.3f} m and x/z "
            f"{ratios.min():+.3f} to {ratios.max():+.3f}, which do not separate the two "
            f"initial directions ({err})",
            outcomes,
        ) from err
    alpha_e = (float(fit.alpha_e[0]), float(fit.alpha_e[1]))
    calibrated = replace(base, alpha_e=alpha_e)
    vertical = None
    lines = None
    offsets = base.head_belief(sim).side_offset_m
    if extended and lines_of_sight and len(rows) >= 3:
        # Off by default: on a head whose centres are on their axes the two
        # extra unknowns only add their calibration noise (about 0.01 % of depth).
        positions = np.array([r[0] for r in rows])
        lines = calibrate_lines_of_sight(
            np.array(alpha1),
            np.array(alpha2),
            positions,
            baseline,
            # A floor of 0.1 mm: the servo's own scatter when the tape is exact.
            sigma_position=max(position_noise_m, depth_noise_m, 1e-4),
            sigma_encoder=sim.settings.encoder_resolution_rad * 0.3,
            initial=alpha_e,
        )
        if lines.separable:
            alpha_e = (float(lines.alpha_e[0]), float(lines.alpha_e[1]))
            offsets = (float(lines.offset_m[0]), float(lines.offset_m[1]))
            calibrated = replace(calibrated, alpha_e=alpha_e, los_offset_m=offsets)
        else:  # the layout cannot tell offsets from directions: keep Sec. V's and the belief's
            calibrated = replace(calibrated, los_offset_m=None)
    if extended and len(rows) >= 3:
        heights = measured_rows[:, 1] / measured_rows[:, 2]
        if np.ptp(heights) < 1e-6:
            raise CalibrationError(
                f"the extended fit (v0, kx/ky) needs a vertical spread, but the "
                f"{len(rows)} fixated positions all have y/z = {heights[0]:+.4f}: set "
                "experiment.calibration.vertical > 0, or extended = false",
                outcomes,
            )
        try:
            vertical = _vertical_from_samples(sim, rows, alpha_e, base, offsets)
        except ValueError as err:
            raise CalibrationError(
                f"degenerate layout for the extended fit because {err}", outcomes
            ) from err
        calibrated = replace(
            calibrated,
            v0=(vertical[0].v0, vertical[1].v0),
            kx_over_ky=(vertical[0].kx_over_ky, vertical[1].kx_over_ky),
        )
    truth = tuple(
        sim.truth.effective_initial_direction(camera, base.reference(sim, camera)[0])
        for camera in (1, 2)
    )
    return CalibrationRun(
        fit=fit,
        truth_alpha_e=(truth[0], truth[1]),
        samples=len(alpha1),
        renders=sim.render_count - start,
        depth_noise_m=depth_noise_m,
        vertical=vertical,
        knowledge=calibrated,
        lines=lines,
        position_noise_m=position_noise_m,
        outcomes=tuple(outcomes),
    )


@dataclass(frozen=True)
class LineOfSightTruth:
    """Each goal column's true line-of-sight offset from its *believed* yaw axis, m.

    ``offset_m``: (s1, s2) along each camera's x, at eye angle 0 and the image
    centre row: the optical centre's own offset ``e cos t - n sin t`` plus the
    axis's true-minus-believed position (half the baseline error, outward).
    ``effective_baseline_m``: believed D - s1 + s2 = true D - s1_own + s2_own.
    """

    offset_m: tuple[float, float]
    effective_baseline_m: float


def line_of_sight_truth(sim: ServoHead, knowledge: HeadKnowledge) -> LineOfSightTruth:
    """Ground truth for the extended calibration's offsets (scoring only)."""
    believed = knowledge.head_belief(sim).baseline_m
    half_error = 0.5 * (sim.truth.settings.baseline_m - believed)
    out = []
    for camera, sign in ((1, -1.0), (2, 1.0)):
        cam = sim.truth.camera_settings(camera)
        u0 = knowledge.reference(sim, camera)[0]
        t = float(cam.pinhole().column_angle(u0))
        own = cam.side_offset_m * math.cos(t) - cam.nodal_offset_m * math.sin(t)
        out.append(own + sign * half_error)
    return LineOfSightTruth((out[0], out[1]), believed - out[0] + out[1])


def _vertical_from_samples(
    sim: ServoHead,
    rows: list[tuple[np.ndarray, dict[str, float]]],
    alpha_e: tuple[float, float],
    base: HeadKnowledge,
    offsets: tuple[float, float] = (0.0, 0.0),
) -> tuple[VerticalCalibration, VerticalCalibration]:
    """Fit (v0, kx/ky) per camera from the calibration fixations at measured positions."""
    truth = np.array([r[0] for r in rows])
    d = {key: np.array([r[1][key] for r in rows]) for key in rows[0][1]}
    z = truth[:, 2]
    a1, a2 = d["alpha1_rad"] + alpha_e[0], d["alpha2_rad"] + alpha_e[1]
    s1, s2 = offsets
    # P's x in each camera's effective frame when its y image was taken (eqs. 8, 10,
    # with the line-of-sight offsets as in headsim.estimators.model2).
    rel1 = d["alpha1_rad"] - d["gamma1_rad"]
    rel2 = d["gamma2_rad"] - d["alpha2_rad"]
    x_c1 = (z + s1 * np.sin(a1)) / np.cos(a1) * np.sin(rel1) + s1 * (np.cos(rel1) - 1.0)
    x_c2 = (z - s2 * np.sin(a2)) / np.cos(a2) * np.sin(rel2) + s2 * (np.cos(rel2) - 1.0)
    u10, u20 = base.reference(sim, 1)[0], base.reference(sim, 2)[0]
    cam1 = calibrate_vertical_reference(d["u11_px"] - u10, d["v11_px"], x_c1, truth[:, 1])
    cam2 = calibrate_vertical_reference(d["u21_px"] - u20, d["v21_px"], x_c2, truth[:, 1])
    return cam1, cam2


__all__ = [
    "CalibrationError",
    "CalibrationRun",
    "LineOfSightTruth",
    "calibrate_head",
    "line_of_sight_truth",
    "tape_measure",
]
