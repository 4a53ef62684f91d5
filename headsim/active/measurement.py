"""What a measurement procedure works with and returns: the head's knowledge of
itself, a target, and one measured point beside the truth.

What the head may know about itself is a :class:`HeadKnowledge` (initial
directions, and optionally vertical references and kx/ky ratios from the
extended calibration); nothing in a procedure reads an intrinsic parameter.
A :class:`Measurement` holds the estimate, its first-order covariance, the
simulator's truth and the error, in H and W, m.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from headsim.active.failure import Failure, FailureCause
from headsim.active.servo_types import Detector
from headsim.estimators import PositionEstimate
from headsim.estimators.result import Method, Status
from headsim.head.servo_head import NoTruth, ServoHead, Specified
from headsim.sim.model import neck_of
from headsim.sim.settings import HeadBelief, HeadSettings

#: Centroid precision assumed for covariances, px (measured: ~0.03-0.06 px).
NOMINAL_PIXEL_SIGMA = 0.05


@dataclass(frozen=True)
class HeadKnowledge:
    """What the head knows about itself; no focal length, no principal point's u.

    ``alpha_e``: each eye's initial direction, rad (0 until calibrated).
    ``v0``: each camera's vertical reference row, px (None: the image centre
    row, the paper's Table VI condition; the principal point's v is Table V).
    ``kx_over_ky``: each camera's pixel aspect ratio (1 unless calibrated).
    ``u0``: each camera's goal column for the servo, px (None: the image
    centre's; e.g. the principal point's column found from a zoom,
    ``headsim.active.principal``).  The initial directions belong to these columns.
    ``belief``: the head's own geometry (baseline, neck D-H, optical-centre
    offsets; None: the simulator's ``belief``, its design, never its truth).
    ``los_offset_m``: how far each goal column's line of sight misses its
    eye's yaw axis, m, along the camera's x (None: the belief's side offsets,
    until the extended calibration measures them).
    """

    alpha_e: tuple[float, float] = (0.0, 0.0)
    v0: tuple[float | None, float | None] = (None, None)
    kx_over_ky: tuple[float, float] = (1.0, 1.0)
    u0: tuple[float | None, float | None] = (None, None)
    belief: HeadBelief | None = None
    los_offset_m: tuple[float, float] | None = None

    def head_belief(self, sim: Specified) -> HeadBelief:
        """The geometry the head believes it has."""
        return self.head_belief_of(sim.settings)

    def head_belief_of(self, settings: HeadSettings) -> HeadBelief:
        """The geometry the head ``settings`` believes it has."""
        return self.belief if self.belief is not None else settings.believed

    def line_of_sight_offsets(self, sim: Specified) -> tuple[float, float]:
        """(s1, s2), m: calibrated, else the believed side offsets."""
        return self.line_of_sight_offsets_of(sim.settings)

    def line_of_sight_offsets_of(self, settings: HeadSettings) -> tuple[float, float]:
        """(s1, s2), m, of the head ``settings``: calibrated, else the believed side offsets."""
        if self.los_offset_m is not None:
            return self.los_offset_m
        return self.head_belief_of(settings).side_offset_m

    def reference(self, sim: Specified, camera: int) -> tuple[float, float]:
        """(u_i0, v_i0): the servo's goal column and the reference row of camera 1 or 2, px."""
        return self.reference_of(sim.settings, camera)

    def reference_of(self, settings: HeadSettings, camera: int) -> tuple[float, float]:
        """(u_i0, v_i0) of camera 1 or 2 of the head ``settings``, px (:meth:`reference`)."""
        u_c, v_c = settings.cameras[camera - 1].image_centre
        u0, v0 = self.u0[camera - 1], self.v0[camera - 1]
        return (u_c if u0 is None else u0, v_c if v0 is None else v0)


@dataclass(frozen=True)
class Target:
    """Something to measure: a name, how to find it in an image, and where it truly is
    (``truth_world``: read from the head's truth channel, for scoring)."""

    name: str
    detector: Detector
    truth_world: Callable[[ServoHead], np.ndarray]


def body_target(name: str, detector: Detector) -> Target:
    """A target whose true position is a body's origin (markers, the block cross point)."""
    return Target(name, detector, lambda sim: sim.truth.position(name))


@dataclass(frozen=True)
class Measurement:
    """One measured point: estimate and truth in H and W, m; covariance in H, m^2.

    ``status``: :attr:`Status.OK` or :attr:`Status.FAILED`; ``detail``: why it
    failed (``failure.message``), "" when ok; ``status_text``: results.json's "status".
    ``renders``: images this measurement took, ``search_renders`` of them
    spent finding a lost target again, ``scan_renders`` of those scanning
    for a target that the pose the head was at did not show (a new target;
    ``headsim.active.search.scan_eyes``/``scan_neck``).  ``servo_residual_px``: the final
    |u - u_i0| of each servo.  ``details``: angles and pixels used.
    ``failure``: the cause, None when ok.
    """

    name: str
    method: Method
    status: Status
    estimate_head_m: np.ndarray
    truth_head_m: np.ndarray
    estimate_world_m: np.ndarray
    truth_world_m: np.ndarray
    covariance_head_m2: np.ndarray
    renders: int
    servo_residual_px: tuple[float, ...]
    details: dict[str, float] = field(default_factory=dict)
    failure: Failure | None = None
    search_renders: int = 0
    detail: str = ""
    scan_renders: int = 0

    @property
    def ok(self) -> bool:
        return self.status is Status.OK

    @property
    def status_text(self) -> str:
        """ "ok", or why it failed."""
        return "ok" if self.ok else self.detail

    @property
    def error_head_m(self) -> np.ndarray:
        """Estimate minus truth in H, m."""
        return self.estimate_head_m - self.truth_head_m

    @property
    def depth_m(self) -> float:
        """True depth z_h, m."""
        return float(self.truth_head_m[2])

    @property
    def error_pct_of_depth(self) -> float:
        """3-D error as a percentage of the true depth."""
        return float(100.0 * np.linalg.norm(self.error_head_m) / self.depth_m)


def _nan3() -> np.ndarray:
    return np.full(3, np.nan)


def _truth(sim: ServoHead, target: Target) -> tuple[np.ndarray, np.ndarray]:
    """The target's true position in W and in H, m; NaN on a head with no truth (a replay)."""
    try:
        truth_world = target.truth_world(sim)
        return truth_world, sim.truth.transform_points(truth_world, "world", "head")[0]
    except NoTruth:
        return _nan3(), _nan3()


def failed_measurement(
    sim: ServoHead,
    target: Target,
    method: str,
    failure: Failure,
    renders: int,
    residuals: Sequence[float],
    search_renders: int = 0,
    scan_renders: int = 0,
) -> Measurement:
    truth_world, truth_head = _truth(sim, target)
    return Measurement(
        name=target.name,
        method=Method(method),
        status=Status.FAILED,
        detail=failure.message,
        failure=failure,
        search_renders=search_renders,
        scan_renders=scan_renders,
        estimate_head_m=_nan3(),
        truth_head_m=truth_head,
        estimate_world_m=_nan3(),
        truth_world_m=truth_world,
        covariance_head_m2=np.full((3, 3), np.nan),
        renders=renders,
        servo_residual_px=tuple(residuals),
    )


def estimated_measurement(
    sim: ServoHead,
    target: Target,
    method: str,
    estimate: PositionEstimate,
    start: int,
    residuals: tuple[float, ...],
    details: dict[str, float],
    neck_rad: tuple[float, float] | None = None,
    belief: HeadBelief | None = None,
    search: int = 0,
    scan: int = 0,
) -> Measurement:
    """The measurement of one estimated point (or why it is invalid) beside the truth."""
    renders = sim.render_count - start
    if not bool(estimate.valid[0]):
        failure = Failure(FailureCause.ESTIMATOR, "estimate", None, repr(estimate.reasons(0)))
        return failed_measurement(sim, target, method, failure, renders, residuals, search, scan)
    truth_world, truth_head = _truth(sim, target)
    estimate_head = estimate.positions[0]
    covariance = estimate.covariance
    return Measurement(
        name=target.name,
        method=Method(method),
        status=Status.OK,
        estimate_head_m=estimate_head,
        truth_head_m=truth_head,
        estimate_world_m=to_world(sim, estimate_head, neck_rad, belief),
        truth_world_m=truth_world,
        covariance_head_m2=covariance[0] if covariance is not None else np.full((3, 3), np.nan),
        renders=renders,
        servo_residual_px=residuals,
        details=details,
        search_renders=search,
        scan_renders=scan,
    )


def encoder_sigma_rad(resolution_rad: float, interpolate: bool) -> float:
    """The std of an encoder angle the servo hands an estimator, rad: 0.3 of a step when
    interpolated between steps, a step's rounding, step / sqrt(12), when whole."""
    return resolution_rad * (0.3 if interpolate else 1 / math.sqrt(12.0))


def to_world(
    sim: ServoHead,
    point_head: np.ndarray,
    neck_rad: tuple[float, float] | None = None,
    belief: HeadBelief | None = None,
) -> np.ndarray:
    """A head-frame estimate in W through eq. (3) (or the head's own neck, (H10)) with the
    believed D-H lengths (default ``sim.belief``), with the neck encoder readings by default."""
    theta1, theta2 = sim.neck_encoders() if neck_rad is None else neck_rad
    b = belief if belief is not None else sim.belief
    neck = neck_of(sim.settings.head)
    return neck.head_to_world(point_head, theta1, theta2, b.neck_d1_m, b.neck_a2_m)


__all__ = [
    "NOMINAL_PIXEL_SIGMA",
    "HeadKnowledge",
    "Measurement",
    "Target",
    "body_target",
    "encoder_sigma_rad",
    "estimated_measurement",
    "failed_measurement",
    "to_world",
]
