"""Result and input types shared by the estimators, and the checks at their entry."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from headsim.geometry.kinematics import ENCODER_RESOLUTION, world_from_head

__all__ = ["Flag", "Method", "PositionEstimate", "Status", "Uncertainty"]


class Method(enum.Enum):
    """Which estimator measured a point; the value is its name in results.json."""

    #: Model 1 (:mod:`headsim.estimators.model1`), fixated by the neck servo
    MODEL1 = "model1"
    #: Model 2 (:mod:`headsim.estimators.model2`), fixated by the eye servo
    MODEL2 = "model2"
    #: One-step fixation with independent eyes (:mod:`headsim.estimators.fixation`)
    FIXATION = "fixation"
    #: Both eyes' images of a recording triangulated where they stood
    #: (:mod:`headsim.head.stereo_look`, ``headsim estimate``)
    STEREO_TRIANGULATION = "stereo_triangulation"


class Status(enum.Enum):
    """Whether a measurement (or a calibration) succeeded; why not is its ``detail`` text."""

    OK = "ok"
    FAILED = "failed"


class Flag(enum.IntFlag):
    """Why an estimate is invalid or degraded; bits combine per point."""

    NONE = 0
    #: an input of this point is NaN or infinite
    NONFINITE = enum.auto()
    #: the two lines of sight do not meet in front: true yaws a1 + a2 <= 0
    NOT_CONVERGING = enum.auto()
    #: a true yaw is at or beyond +-pi/2, or a y image was taken with P behind the camera
    BEHIND_CAMERA = enum.auto()
    #: |u1d| below the threshold: eq. (9) is 0/0; y_h comes from camera 2 alone
    SMALL_U1D = enum.auto()
    #: |u2d| below the threshold: eq. (10) is 0/0; y_h comes from camera 1 alone
    SMALL_U2D = enum.auto()
    #: both images are too near their target columns: y_h is undetermined
    NO_Y = enum.auto()

    @classmethod
    def fatal(cls) -> Flag:
        """The bits that make an estimate invalid."""
        return cls.NONFINITE | cls.NOT_CONVERGING | cls.BEHIND_CAMERA | cls.NO_Y


@dataclass(frozen=True)
class Uncertainty:
    """Independent 1-sigma input errors: baseline, m; each encoder reading, rad; each pixel, px.

    Fixation residuals (P not exactly on its target column) act as eye-angle
    errors of ``residual_px / kx`` rad: fold them into ``encoder``.
    """

    baseline: float = 0.0
    encoder: float = 0.0
    pixel: float = 0.0

    def __post_init__(self) -> None:
        for name in ("baseline", "encoder", "pixel"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(
                    f"Uncertainty.{name} must be a finite standard deviation >= 0, got {value!r}"
                )

    @classmethod
    def quantised(
        cls, resolution: float = ENCODER_RESOLUTION, *, baseline: float = 0.0, pixel: float = 0.0
    ) -> Uncertainty:
        """Encoder error of rounding to steps of ``resolution`` rad: resolution / sqrt(12)."""
        return cls(baseline=baseline, encoder=resolution / math.sqrt(12.0), pixel=pixel)


@dataclass(frozen=True)
class PositionEstimate:
    """Estimated positions of N points with validity and, optionally, covariance.

    positions: (N, 3) in ``frame`` ("H" head or "W" world), m; NaN where invalid.
    valid: (N,) bool.  flags: (N,) int, :class:`Flag` bits (0 = clean).
    covariance: (N, 3, 3) first-order covariance in the same frame, m^2, or None.
    y_cam: (N, 2) y of P from Ca1's eq. (9) and Ca2's eq. (10), m (Model 2 only;
    NaN where that camera was not used), or None.
    """

    positions: np.ndarray
    valid: np.ndarray
    flags: np.ndarray
    covariance: np.ndarray | None = None
    y_cam: np.ndarray | None = None
    frame: str = "H"

    def reasons(self, i: int) -> Flag:
        """The flags of point ``i`` as a :class:`Flag`."""
        return Flag(int(self.flags[i]))

    def to_world(
        self, theta1: ArrayLike, theta2: ArrayLike, d1: float, a2: float
    ) -> PositionEstimate:
        """The same estimate in W by eq. (1); neck angles, rad, scalar or (N,), taken as exact."""
        if self.frame != "H":
            raise ValueError(
                f"to_world needs an estimate in the head frame H, this one is in {self.frame}"
            )
        t = world_from_head(theta1, theta2, d1, a2)
        r, c = t[..., :3, :3], t[..., :3, 3]
        positions = np.einsum("...ij,...j->...i", r, self.positions) + c
        cov = None
        if self.covariance is not None:
            cov = np.einsum("...ij,...jk,...lk->...il", r, self.covariance, r)
        return PositionEstimate(positions, self.valid, self.flags, cov, self.y_cam, frame="W")


def as_vector(a: ArrayLike, name: str) -> np.ndarray:
    """A float array of shape (N,) from a scalar or 1-D input."""
    v = np.asarray(a, dtype=float)
    if v.ndim == 0:
        v = v.reshape(1)
    if v.ndim != 1:
        raise ValueError(f"{name} must be a scalar or have shape (N,), got {v.shape}")
    return v


def as_pixels(a: ArrayLike, name: str, n: int) -> np.ndarray:
    """A float array of shape (n, 2) of pixel coordinates."""
    uv = np.asarray(a, dtype=float)
    if uv.ndim == 1 and uv.shape == (2,):
        uv = uv.reshape(1, 2)
    if uv.ndim != 2 or uv.shape[1] != 2 or uv.shape[0] != n:
        raise ValueError(f"{name} must have shape ({n}, 2) (u, v in px), got {uv.shape}")
    return uv


def check_angles(a: np.ndarray, name: str) -> None:
    """Raise if finite angles are clearly not radians."""
    if np.any(np.abs(a) > math.pi):
        raise ValueError(
            f"{name} must be in radians with |angle| <= pi; got up to {np.nanmax(np.abs(a))!r}"
        )


def check_baseline(baseline: float) -> float:
    """The baseline D as a float, m; raise unless 0 < D < 10 m."""
    d = float(baseline)
    if not (math.isfinite(d) and 0.0 < d < 10.0):
        raise ValueError(f"baseline must be in metres, 0 < D < 10, got {baseline!r}")
    return d
