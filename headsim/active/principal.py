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

**Servoing to it**: ``HeadKnowledge(u0=columns)`` makes ``measure_model2``
servo each camera to its column, and ``calibrate_head(..., knowledge=...)``
calibrates the initial directions on those columns; the simulator's truth
for them is ``HeadSim.effective_initial_direction(camera, goal_u)``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from headsim.active.chessboard import look_for_board
from headsim.head.servo_head import ServoHead
from headsim.sim import names
from headsim.sim.settings import HeadSettings
from headsim.stereo.views import place_chessboard, sample_board_pose

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
    first, second = (c.with_zoom(factor) for c in settings.cameras)
    return replace(settings, cameras=(first, second))


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
    before: ServoHead,
    after: ServoHead,
    zoom: float = PROBE_ZOOM,
    rng: np.random.Generator | None = None,
    poses: int = 2,
    distance_range_m: tuple[float, float] | None = None,
) -> PrincipalPointRun:
    """Find each camera's principal point as the fixed point of a zoom, from chessboard images.

    ``before`` and ``after``: the head in the chessboard scene at its focal
    lengths and at ``zoom`` times them (``after.settings`` is
    ``zoomed(before.settings, zoom)``).  The chessboard is placed in ``poses``
    seeded poses (seen whole at both focal lengths: the poses are drawn for
    the longer one); for each, both eyes at angle 0 render it in both
    simulators, and the corners found in both images of one camera are
    matched by their board order.  Only pixels enter the fit.
    ``distance_range_m`` of the board defaults to 0.5-0.9 m times the zoomed
    head's :func:`view_scale` (a narrower view needs the board further away).
    """
    settings = before.truth.settings
    if after.truth.settings != zoomed(settings, zoom):
        raise ValueError(
            f"principal points: after.settings must be before.settings zoomed {zoom}x "
            "(zoomed(before.settings, zoom))"
        )
    rng = rng or np.random.default_rng(0)
    narrow = after.truth.settings if zoom > 1 else settings
    if distance_range_m is None:
        scale = view_scale(narrow)
        distance_range_m = (0.5 * scale, 0.9 * scale)
    matched: list[list[tuple[np.ndarray, np.ndarray]]] = [[], []]
    renders = views = 0
    sims = (before, after)
    for sim in sims:
        sim.move(eye=0.0, neck_yaw=0.0, neck_pitch=0.0)
    sampler = after if zoom > 1 else before
    for _ in range(poses):
        head_from_board = sample_board_pose(sampler.truth, rng, distance_range_m, max_tilt_rad=0.4)
        for sim in sims:
            place_chessboard(sim.truth, head_from_board)
        found_any = False
        for camera in (1, 2):
            corners = [look_for_board(sim, camera) for sim in sims]
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


__all__ = [
    "PROBE_ZOOM",
    "PrincipalPointError",
    "PrincipalPointRun",
    "ZoomFixedPoint",
    "fixed_point_of_zoom",
    "principal_points_by_zoom",
    "view_scale",
    "zoomed",
]
