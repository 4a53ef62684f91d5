"""The principal point from images alone, and the active method servoing to it.

**Why.**  The paper's eye servo centres the target on the image centre's
column.  The Sec. V calibration then measures the *effective* initial
direction: the mount yaw plus the angle of the image centre's ray off the
optical axis, about ``atan((u_centre - cx) / kx)``.  That angle depends on the
focal length, so with an off-centre principal point a zoom turns the ray and
the calibrated offsets go stale.  The column through the principal point is
different: a radial lens keeps x = 0 on it, so its rays lie in the camera's
y-z plane at every row, every focal length and every k1.  Servoing to that
column makes the calibrated offset the mount yaw itself, which no zoom moves.

**Finding it** (:func:`fixed_point_of_zoom`).  A pure zoom scales every image
point about the principal point c: ``p' - c = s (p - c)`` with s = f' / f.
The simulator's lens is radial in normalised coordinates, so this holds with
distortion too (a real zoom lens also changes its distortion a little; the
residual says how much).  With features seen at two focal lengths from one
pose, ``p' = s p + t`` is linear in (s, t); least squares gives them and
``c = t / (1 - s)``.  No intrinsic parameter, no known geometry: only which
feature is which.  :func:`principal_points_by_zoom` does it in the simulator
with the chessboard's 48 corners, both eyes at angle 0.

**Servoing to it** (:class:`GoalServo`, :class:`GoalKnowledge`): the eye servo
and the head's knowledge with a goal column per camera instead of the image
centre.  Both subclass the procedures' own types, so ``measure_model2`` takes
them unchanged; :func:`calibrate_head_on_columns` is ``calibrate_head`` with
the goal columns also in its vertical fit (which assumes the image centre's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from headsim import names
from headsim.estimators.calibration import calibrate_initial_directions
from headsim.estimators.vertical import VerticalCalibration, calibrate_vertical_reference
from headsim.model import eye_from_camera_rotation
from headsim.procedures import CalibrationRun, HeadKnowledge, Model2Config, Target, measure_model2
from headsim.servo import Detection, Detector, EyeServo, ServoConfig, ServoResult
from headsim.settings import HeadSettings
from headsim.sim import HeadSim
from headsim.stereo import (
    detect_chessboard,
    place_chessboard,
    sample_board_pose,
    undistort_normalized_points,
)

#: Zoom used to find the principal point when the study needs one (f' = 1.3 f).
PROBE_ZOOM = 1.3


class PrincipalPointError(ValueError):
    """The principal point cannot be found (no zoom between the images, too few features)."""


@dataclass(frozen=True)
class ZoomFixedPoint:
    """The point an image zoom leaves in place, from matched features.

    ``principal_px`` (2,): the fixed point (u, v), px; ``scale``: s = f' / f;
    ``covariance_px2`` (2, 2): its first-order covariance from the residual
    scatter; ``residual_rms_px``: RMS distance of ``p'`` from ``s p + t``;
    ``points``: features used.
    """

    principal_px: np.ndarray
    scale: float
    covariance_px2: np.ndarray
    residual_rms_px: float
    points: int

    @property
    def std_px(self) -> np.ndarray:
        """Standard errors of (u, v), px."""
        return np.sqrt(np.diag(self.covariance_px2))


def fixed_point_of_zoom(
    before_px: np.ndarray, after_px: np.ndarray, min_scale_change: float = 0.02
) -> ZoomFixedPoint:
    """Fixed point of the zoom that maps features ``before_px`` (N, 2) to ``after_px`` (N, 2), px.

    Model ``p' = s p + t`` (s: scale, t: (2,) shift), solved by linear least
    squares; the fixed point is ``t / (1 - s)``.  Raises
    :class:`PrincipalPointError` for fewer than 3 features, non-finite
    input, or ``|s - 1| < min_scale_change`` (without a zoom every point is
    fixed and none is singled out).
    """
    before = np.asarray(before_px, dtype=float)
    after = np.asarray(after_px, dtype=float)
    if before.ndim != 2 or before.shape[1] != 2 or before.shape != after.shape:
        raise PrincipalPointError(
            f"before_px and after_px must both be (N, 2), got {before.shape} and {after.shape}"
        )
    n = len(before)
    if n < 3:
        raise PrincipalPointError(f"need at least 3 matched features, got {n}")
    if not (np.all(np.isfinite(before)) and np.all(np.isfinite(after))):
        raise PrincipalPointError("feature coordinates must be finite")
    # Unknowns (s, tx, ty); rows: u' = s u + tx, v' = s v + ty.
    design = np.zeros((2 * n, 3))
    design[0::2, 0], design[1::2, 0] = before[:, 0], before[:, 1]
    design[0::2, 1] = design[1::2, 2] = 1.0
    rhs = after.reshape(-1)
    params, *_ = np.linalg.lstsq(design, rhs, rcond=None)
    s, t = float(params[0]), params[1:]
    if abs(s - 1.0) < min_scale_change:
        raise PrincipalPointError(
            f"the images differ by a scale of {s:.4f}: no zoom, so no fixed point "
            f"(need |s - 1| >= {min_scale_change})"
        )
    residuals = rhs - design @ params
    dof = max(2 * n - 3, 1)
    sigma2 = float(residuals @ residuals) / dof
    params_cov = sigma2 * np.linalg.inv(design.T @ design)
    centre = t / (1.0 - s)
    # c = t / (1 - s): Jacobian with respect to (s, tx, ty).
    jac = np.zeros((2, 3))
    jac[:, 0] = t / (1.0 - s) ** 2
    jac[0, 1] = jac[1, 2] = 1.0 / (1.0 - s)
    return ZoomFixedPoint(
        principal_px=centre,
        scale=s,
        covariance_px2=jac @ params_cov @ jac.T,
        residual_rms_px=float(np.sqrt(np.mean(residuals.reshape(-1, 2) ** 2) * 2)),
        points=n,
    )


def view_scale(settings: HeadSettings, reference_focal_px: float = 850.0) -> float:
    """How much further than usual a calibration target must be to fit a narrow view (>= 1).

    The largest focal length over ``reference_focal_px`` (the paper's cameras),
    at least 1: boards and targets placed for the paper's cameras go that
    much further away for a longer lens.  For placing targets only.
    """
    return max(1.0, max(c.kx for c in settings.cameras) / reference_focal_px)


def zoomed(settings: HeadSettings, factor: float) -> HeadSettings:
    """The same head with both cameras' focal lengths scaled by ``factor``."""
    return replace(settings, cameras=tuple(c.with_zoom(factor) for c in settings.cameras))


@dataclass(frozen=True)
class PrincipalPointRun:
    """Both cameras' zoom fixed points beside the simulator's principal points.

    ``fits``: per camera (Ca1, Ca2); ``truth_px``: the true (cx, cy) per
    camera; ``zoom``: the focal length ratio used; ``views``: board poses
    whose corners were found at both focal lengths; ``renders``: images taken.
    """

    fits: tuple[ZoomFixedPoint, ZoomFixedPoint]
    truth_px: tuple[tuple[float, float], tuple[float, float]]
    zoom: float
    views: int
    renders: int

    @property
    def principal_px(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Recovered (u, v) per camera, px."""
        return tuple(  # type: ignore[return-value]
            (float(f.principal_px[0]), float(f.principal_px[1])) for f in self.fits
        )

    @property
    def errors_px(self) -> np.ndarray:
        """(2, 2): recovered minus true (u, v) per camera, px."""
        return np.array([f.principal_px for f in self.fits]) - np.array(self.truth_px)


def principal_points_by_zoom(
    settings: HeadSettings,
    zoom: float = PROBE_ZOOM,
    rng: np.random.Generator | None = None,
    poses: int = 2,
    distance_range_m: tuple[float, float] | None = None,
) -> PrincipalPointRun:
    """Find each camera's principal point as the fixed point of a zoom, from chessboard images.

    The chessboard is placed in ``poses`` seeded poses (seen whole at both
    focal lengths: the poses are drawn for the longer one); for each, both
    eyes at angle 0 render it at the head's focal lengths and at ``zoom``
    times them, and the corners found in both images of one camera are
    matched by their board order.  Only pixels enter the fit.
    ``distance_range_m`` of the board defaults to 0.5-0.9 m times the zoomed
    head's :func:`view_scale` (a narrower view needs the board further away).
    """
    rng = rng or np.random.default_rng(0)
    after_settings = zoomed(settings, zoom)
    narrow = after_settings if zoom > 1 else settings
    if distance_range_m is None:
        scale = view_scale(narrow)
        distance_range_m = (0.5 * scale, 0.9 * scale)
    matched: list[list[tuple[np.ndarray, np.ndarray]]] = [[], []]
    renders = views = 0
    with (
        HeadSim("chessboard", settings) as before,
        HeadSim("chessboard", after_settings) as after,
    ):
        sims = (before, after)
        for sim in sims:
            sim.move(eye=0.0, neck_yaw=0.0, neck_pitch=0.0)
        sampler = after if narrow is after_settings else before
        for _ in range(poses):
            head_from_board = sample_board_pose(sampler, rng, distance_range_m, max_tilt_rad=0.4)
            for sim in sims:
                place_chessboard(sim, head_from_board)
            found_any = False
            for camera in (1, 2):
                corners = [detect_chessboard(sim.render(camera)) for sim in sims]
                renders += 2
                if corners[0] is not None and corners[1] is not None:
                    matched[camera - 1].append((corners[0], corners[1]))
                    found_any = True
            views += found_any
    fits = []
    for camera in (1, 2):
        if not matched[camera - 1]:
            raise PrincipalPointError(
                f"the chessboard was not found at both focal lengths in "
                f"{names.CAMERAS[camera - 1]} in any of {poses} poses"
            )
        before_px = np.concatenate([m[0] for m in matched[camera - 1]])
        after_px = np.concatenate([m[1] for m in matched[camera - 1]])
        fits.append(fixed_point_of_zoom(before_px, after_px))
    truth = tuple(c.principal for c in settings.cameras)
    return PrincipalPointRun(
        fits=(fits[0], fits[1]),
        truth_px=(truth[0], truth[1]),
        zoom=zoom,
        views=views,
        renders=renders,
    )


# -- the active method with a goal column per camera ---------------------------


class GoalServo(EyeServo):
    """:class:`EyeServo` whose default goal column is ``goal_columns[camera - 1]``, px.

    Everything else (gains, bounds, sub-step interpolation) is the eye servo's.
    """

    def __init__(
        self, sim: HeadSim, goal_columns: tuple[float, float], config: ServoConfig | None = None
    ) -> None:
        super().__init__(sim, config)
        for camera, u in zip((1, 2), goal_columns, strict=True):
            width = sim.camera_settings(camera).width
            if not (math.isfinite(u) and 0 <= u <= width - 1):
                raise ValueError(
                    f"goal column of camera {camera} must lie in the image [0, {width - 1}], got {u}"
                )
        self.goal_columns = (float(goal_columns[0]), float(goal_columns[1]))

    def run(
        self,
        camera: int,
        detector: Detector,
        goal_u: float | None = None,
        first: Detection | None = None,
    ) -> ServoResult:
        goal = self.goal_columns[camera - 1] if goal_u is None else goal_u
        return super().run(camera, detector, goal_u=goal, first=first)


@dataclass(frozen=True)
class GoalKnowledge(HeadKnowledge):
    """:class:`HeadKnowledge` with each camera's goal column ``u0`` (None: the image centre's).

    Pair it with a :class:`GoalServo` on the same columns: the estimator's
    u_i0 must be the column the servo centred the target on.
    """

    u0: tuple[float | None, float | None] = (None, None)

    def reference(self, sim: HeadSim, camera: int) -> tuple[float, float]:
        u, v = super().reference(sim, camera)
        u0 = self.u0[camera - 1]
        return (u if u0 is None else u0, v)


def column_direction(sim: HeadSim, camera: int, u_px: float) -> float:
    """True horizontal direction of image column ``u_px`` at the principal row, rad, + inward.

    In the eye frame at eye angle 0, like ``HeadSim.effective_initial_direction``
    (which is this at the image centre's column, give or take the row): what
    the Sec. V calibration finds when the servo centres targets on that
    column.  At the principal point's column it is the mount yaw.  Truth, for
    scoring only.
    """
    index = sim.camera_index(camera)
    cam = sim.settings.cameras[index]
    _, cy = cam.principal
    xy = undistort_normalized_points(
        np.array([[u_px, cy]]), sim.camera_matrix(camera), sim.dist_coeffs(camera)
    )[0]
    ray = eye_from_camera_rotation(cam, index) @ np.array([xy[0], xy[1], 1.0])
    yaw = math.atan2(ray[0], ray[2])
    return yaw if index == 0 else -yaw


def calibrate_head_on_columns(
    sim: HeadSim,
    servo: GoalServo,
    target: Target,
    body: str,
    positions_world: np.ndarray,
    *,
    extended: bool = True,
) -> CalibrationRun:
    """``procedures.calibrate_head`` with the servo on ``servo.goal_columns`` instead of the image centre.

    The same Sec. V fit of the initial directions (unweighted, exact depths)
    and, with ``extended``, the same vertical fit per camera, with each
    camera's goal column as u_i0.  The returned knowledge is a
    :class:`GoalKnowledge` on those columns; ``truth_alpha_e`` is the true
    direction of each goal column (:func:`column_direction`).  A thin
    variant: ``calibrate_head`` taking a base ``HeadKnowledge`` would make it
    unnecessary.
    """
    start = sim.render_count
    base = GoalKnowledge(u0=servo.goal_columns)
    plain = Model2Config(midline_px=0.0)
    alpha1, alpha2, depths = [], [], []
    rows: list[tuple[np.ndarray, dict[str, float]]] = []
    positions = np.atleast_2d(positions_world)
    for position in positions:
        sim.set_body_pose(body, position)
        m = measure_model2(sim, servo, target, base, plain)
        if not m.ok:
            continue
        alpha1.append(m.details["alpha1_rad"])
        alpha2.append(m.details["alpha2_rad"])
        depths.append(float(m.truth_head_m[2]))
        rows.append((m.truth_head_m, m.details))
    if len(alpha1) < 2:
        raise ValueError(
            f"calibration needs at least 2 fixated targets, got {len(alpha1)} of "
            f"{len(positions)}: place them where both cameras see them"
        )
    baseline = sim.settings.baseline_m
    fit = calibrate_initial_directions(
        np.array(alpha1), np.array(alpha2), np.array(depths), baseline
    )
    alpha_e = (float(fit.alpha_e[0]), float(fit.alpha_e[1]))
    knowledge = replace(base, alpha_e=alpha_e)
    vertical = None
    if extended and len(rows) >= 3:
        vertical = _vertical_on_columns(rows, alpha_e, servo.goal_columns)
        knowledge = replace(
            knowledge,
            v0=(vertical[0].v0, vertical[1].v0),
            kx_over_ky=(vertical[0].kx_over_ky, vertical[1].kx_over_ky),
        )
    truth = tuple(column_direction(sim, c, servo.goal_columns[c - 1]) for c in (1, 2))
    return CalibrationRun(
        fit=fit,
        truth_alpha_e=(truth[0], truth[1]),
        samples=len(alpha1),
        renders=sim.render_count - start,
        depth_noise_m=0.0,
        vertical=vertical,
        knowledge=knowledge,
    )


def _vertical_on_columns(
    rows: list[tuple[np.ndarray, dict[str, float]]],
    alpha_e: tuple[float, float],
    columns: tuple[float, float],
) -> tuple[VerticalCalibration, VerticalCalibration]:
    """(v0, kx/ky) per camera from fixations at known positions, u_i0 = ``columns``.

    As ``procedures._vertical_from_samples``, whose u_i0 is the image centre's.
    """
    truth = np.array([r[0] for r in rows])
    d = {key: np.array([r[1][key] for r in rows]) for key in rows[0][1]}
    z = truth[:, 2]
    a1, a2 = d["alpha1_rad"] + alpha_e[0], d["alpha2_rad"] + alpha_e[1]
    # P's x in each camera's frame when its y image was taken (eqs. 8, 10).
    x_c1 = z * np.sin(d["alpha1_rad"] - d["gamma1_rad"]) / np.cos(a1)
    x_c2 = z * np.sin(d["gamma2_rad"] - d["alpha2_rad"]) / np.cos(a2)
    cam1 = calibrate_vertical_reference(d["u11_px"] - columns[0], d["v11_px"], x_c1, truth[:, 1])
    cam2 = calibrate_vertical_reference(d["u21_px"] - columns[1], d["v21_px"], x_c2, truth[:, 1])
    return cam1, cam2


__all__ = [
    "PROBE_ZOOM",
    "GoalKnowledge",
    "GoalServo",
    "PrincipalPointError",
    "PrincipalPointRun",
    "ZoomFixedPoint",
    "calibrate_head_on_columns",
    "column_direction",
    "fixed_point_of_zoom",
    "principal_points_by_zoom",
    "view_scale",
    "zoomed",
]
