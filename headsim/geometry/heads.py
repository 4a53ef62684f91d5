"""Heads other than the paper's: independent eyes, an eye tilt, a serial-chain neck, version/vergence.

Pure math, no simulator (derivations: docs/equations.md, "Beyond the paper: other
heads").  Frames and signs as there: W world (z up, y forward, x right), H head
(x right from C1 to C2, y down, z forward, origin mid-baseline), E the eye frame
in which the eyes pan (H itself, or H tilted by a common eye tilt).  Eye angles
are positive inwards (Ca1, the left eye, towards +x; Ca2 towards -x).  Transforms
are ``dst_from_src`` 4 x 4 acting on column vectors.  Lengths m, angles rad.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from headsim.geometry import kinematics
from headsim.geometry.synthetic import StereoHead, fixation_angles
from headsim.geometry.transforms import homogeneous, points3

__all__ = [
    "NECK_ORDERS",
    "EyeAxesAlignment",
    "EyePans",
    "Neck",
    "RevoluteJoint",
    "SerialChain",
    "VersionVergence",
    "check_eye_axes",
    "eye_axes_alignment",
    "fixating_eye_angles",
    "fixation_point_from_version_vergence",
    "fixation_point_head",
    "fixation_point_world",
    "head_from_tilted_eyes",
    "inward_from_version_vergence",
    "paper_neck",
    "pitch_roll_yaw_neck",
    "tilt_to_plane",
    "version_vergence",
]

_HALF_PI = math.pi / 2

# H's axes in W at the neck's zero pose: x right, y down, z forward (eq. (1) at theta = 0).
_WORLD_FROM_HEAD_AT_ZERO = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


# --- one-step fixation with two eye motors -------------------------------------------


@dataclass(frozen=True)
class EyePans:
    """The two eyes' pan angles, rad, positive inwards: ``inward1_rad`` Ca1 (left), ``inward2_rad`` Ca2."""

    inward1_rad: np.ndarray
    inward2_rad: np.ndarray


def fixation_point_head(
    alpha1_rad: ArrayLike,
    alpha2_rad: ArrayLike,
    baseline_m: float,
    alpha_e_rad: tuple[float, float] = (0.0, 0.0),
    los_offset_m: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """The point (..., 3) in the eye frame, m, that both eyes fixate at once.

    alpha1_rad, alpha2_rad: each eye's encoder reading, rad, positive inwards, read at
    the same instant (broadcast).  alpha_e_rad: the initial directions (alpha_e1,
    alpha_e2), rad; the true yaws are a_i = alpha_i + alpha_ei.  los_offset_m: (s1, s2),
    m, how far each line of sight misses its eye's pan axis along the camera's x (0 is
    the paper's eye).  The point is in the plane of the optical axes (y = 0):

        z = (D - s1 / cos a1 + s2 / cos a2) / (tan a1 + tan a2),  x = z tan a1 + s1 / cos a1 - D/2

    (eqs. (4), (5) with s = 0).  Raises ValueError where |a_i| >= pi/2, where
    tan a1 + tan a2 <= 0 (the lines of sight are parallel or diverge) or where they
    cross behind the baseline (z <= 0).
    """
    d = _baseline(baseline_m)
    e1, e2 = _pair(alpha_e_rad, "alpha_e_rad")
    s1, s2 = _pair(los_offset_m, "los_offset_m")
    if not (abs(s1) < d / 2 and abs(s2) < d / 2):
        raise ValueError(f"los_offset_m must be offsets in metres, |s| < D/2, got {los_offset_m!r}")
    enc1, enc2 = np.broadcast_arrays(np.asarray(alpha1_rad, float), np.asarray(alpha2_rad, float))
    a1, a2 = enc1 + e1, enc2 + e2
    bad = ~(np.isfinite(a1) & np.isfinite(a2) & (np.abs(a1) < _HALF_PI) & (np.abs(a2) < _HALF_PI))
    _raise_where(bad, a1, a2, "are not finite with |a_i| < pi/2")
    t1, t2 = np.tan(a1), np.tan(a2)
    _raise_where(
        ~(t1 + t2 > 0.0),
        a1,
        a2,
        "give tan a1 + tan a2 <= 0: the lines of sight are parallel or diverge",
    )
    sec1, sec2 = 1.0 / np.cos(a1), 1.0 / np.cos(a2)
    z = (d - s1 * sec1 + s2 * sec2) / (t1 + t2)
    _raise_where(
        ~(z > 0.0), a1, a2, "make the offset lines of sight cross behind the baseline, z <= 0"
    )
    x = z * t1 + s1 * sec1 - 0.5 * d
    return np.stack([x, np.zeros_like(z), z], axis=-1)


def fixation_point_world(
    alpha1_rad: ArrayLike,
    alpha2_rad: ArrayLike,
    baseline_m: float,
    world_from_eyes: np.ndarray,
    alpha_e_rad: tuple[float, float] = (0.0, 0.0),
    los_offset_m: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """The fixated point (..., 3) in W, m: ``world_from_eyes @ fixation_point_head(...)``.

    world_from_eyes: (..., 4, 4) pose of the eye frame in W, e.g.
    ``kinematics.world_from_head(theta1, theta2, d1, a2)`` (eq. (1)), a
    :class:`SerialChain`'s ``world_from_head(...)``, times :func:`head_from_tilted_eyes`
    with an eye tilt.  Other arguments as :func:`fixation_point_head`.
    """
    p = fixation_point_head(alpha1_rad, alpha2_rad, baseline_m, alpha_e_rad, los_offset_m)
    t = np.asarray(world_from_eyes, float)
    if t.shape[-2:] != (4, 4):
        raise ValueError(f"world_from_eyes must have shape (..., 4, 4), got {t.shape}")
    return np.einsum("...ij,...j->...i", t[..., :3, :3], p) + t[..., :3, 3]


def fixating_eye_angles(
    points_eyes: ArrayLike,
    baseline_m: float,
    alpha_e_rad: tuple[float, float] = (0.0, 0.0),
    los_offset_m: tuple[float, float] = (0.0, 0.0),
) -> EyePans:
    """Exact forward model: the encoder readings, rad, that put points (..., 3) of the eye frame on both lines of sight.

    Eye i's line of sight runs along its optical axis, ``s_i`` to the side of its pan
    axis at (-+D/2, 0, 0); with P at horizontal range r_i and azimuth phi_i from that
    axis: a1 = phi1 - asin(s1 / r1), a2 = asin(s2 / r2) - phi2.  It is the project's
    one forward model, :func:`headsim.geometry.synthetic.fixation_angles`, for ideal
    eyes fixating on the principal column with side offsets ``s_i``.  P's y is not
    used: off the plane y = 0 the angles still put P on each line of sight's vertical
    plane.  NaN where a point is not in front of the baseline or an eye would turn to
    +-pi/2 or beyond.
    """
    p = points3(points_eyes, "points_eyes")
    e1, e2 = _pair(alpha_e_rad, "alpha_e_rad")
    s1, s2 = _pair(los_offset_m, "los_offset_m")
    head = StereoHead(_baseline(baseline_m), alpha_e1=e1, alpha_e2=e2, side1=s1, side2=s2)
    fix = fixation_angles(head, p.reshape(-1, 3))
    return EyePans(fix.alpha1.reshape(p.shape[:-1]), fix.alpha2.reshape(p.shape[:-1]))


# --- a common eye tilt -----------------------------------------------------------------


def head_from_tilted_eyes(
    tilt_rad: ArrayLike, tilt_axis_h_m: ArrayLike = (0.0, 0.0, 0.0)
) -> np.ndarray:
    """H_T_E (..., 4, 4): the eye frame E after a common eye tilt, in H.

    tilt_rad: the tilt about H's x, rad, positive looks up (as the neck pitch).
    tilt_axis_h_m: (3,) a point of the tilt axis in H, m (0: the axis is the line
    through both optical centres).  E is H rotated about that axis:
    ``p_H = t + R_x(tau) (p_E - t)``; at tau = 0 it is H.
    """
    t = np.asarray(tilt_axis_h_m, float)
    if t.shape != (3,) or not np.isfinite(t).all():
        raise ValueError(f"tilt_axis_h_m must be a finite point (3,) in metres, got {t!r}")
    tau = np.asarray(tilt_rad, float)
    c, s = np.cos(tau), np.sin(tau)
    out = np.zeros((*tau.shape, 4, 4))
    out[..., 0, 0] = out[..., 3, 3] = 1.0
    out[..., 1, 1], out[..., 1, 2], out[..., 2, 1], out[..., 2, 2] = c, -s, s, c
    # Translation t - R_x(tau) t; x is along the axis and does not move.
    out[..., 1, 3] = t[1] - (c * t[1] - s * t[2])
    out[..., 2, 3] = t[2] - (s * t[1] + c * t[2])
    return out


def tilt_to_plane(points_h: ArrayLike, tilt_axis_h_m: ArrayLike = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Exact forward model: the tilt, rad, that puts points (..., 3) of H in the eyes' plane y_E = 0.

    With q = p_H - t, (q_y, q_z) = rho (sin phi, cos phi):
    y_E = t_y + rho sin(phi + tau) = 0, so tau = -phi - asin(t_y / rho), the branch
    on which P stays ahead of the tilt axis.  NaN where the point is within |t_y| of
    the tilt axis.
    """
    p = points3(points_h, "points_h")
    t = np.asarray(tilt_axis_h_m, float)
    if t.shape != (3,) or not np.isfinite(t).all():
        raise ValueError(f"tilt_axis_h_m must be a finite point (3,) in metres, got {t!r}")
    qy, qz = p[..., 1] - t[1], p[..., 2] - t[2]
    with np.errstate(invalid="ignore"):
        # Positive tilt looks up, towards -y: y_E = cos(tau) qy + sin(tau) qz + t_y.
        return -np.arctan2(qy, qz) - np.arcsin(t[1] / np.hypot(qy, qz))


# --- serial-chain necks ----------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class RevoluteJoint:
    """One revolute joint: its frame at angle 0 in its parent's frame, (4, 4), m, and its unit axis (3,) in that frame."""

    parent_from_joint: np.ndarray
    axis: np.ndarray
    name: str = ""

    def __post_init__(self) -> None:
        pose = np.array(self.parent_from_joint, dtype=float)
        axis = np.array(self.axis, dtype=float)
        if pose.shape != (4, 4) or not _is_rigid(pose):
            raise ValueError(
                f"joint {self.name!r}: parent_from_joint must be a rigid 4 x 4 transform"
            )
        norm = float(np.linalg.norm(axis)) if axis.shape == (3,) else math.nan
        if not abs(norm - 1.0) < 1e-9:
            raise ValueError(
                f"joint {self.name!r}: axis must be a unit vector (3,), got {self.axis!r}"
            )
        object.__setattr__(self, "parent_from_joint", pose)
        object.__setattr__(self, "axis", axis / norm)

    def rotation(self, angle_rad: np.ndarray) -> np.ndarray:
        """Rotation (..., 3, 3) by ``angle_rad`` about the axis: c I + s [a]x + (1 - c) a a^T."""
        a = self.axis
        c, s = np.cos(angle_rad)[..., None, None], np.sin(angle_rad)[..., None, None]
        cross = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
        return c * np.eye(3) + s * cross + (1.0 - c) * np.outer(a, a)


@dataclass(frozen=True, eq=False)
class SerialChain:
    """A neck as a serial chain of revolute joints from W (the base) up, and H in the last joint's frame.

    ``world_from_head(q) = prod_i [parent_from_joint_i Rot(axis_i, q_i)] last_from_head``.
    """

    joints: tuple[RevoluteJoint, ...]
    last_from_head: np.ndarray

    def __post_init__(self) -> None:
        pose = np.array(self.last_from_head, dtype=float)
        if pose.shape != (4, 4) or not _is_rigid(pose):
            raise ValueError("last_from_head must be a rigid 4 x 4 transform")
        object.__setattr__(self, "joints", tuple(self.joints))
        object.__setattr__(self, "last_from_head", pose)

    def world_from_head(self, angles_rad: ArrayLike) -> np.ndarray:
        """W_T_H (..., 4, 4) at joint angles (..., n), rad, base joint first."""
        q = np.asarray(angles_rad, float)
        n = len(self.joints)
        if q.ndim == 0 or q.shape[-1] != n:
            raise ValueError(f"angles_rad must have shape (..., {n}), one per joint, got {q.shape}")
        out = np.broadcast_to(np.eye(4), (*q.shape[:-1], 4, 4)).copy()
        for i, joint in enumerate(self.joints):
            step = np.broadcast_to(joint.parent_from_joint, out.shape).copy()
            step[..., :3, :3] = joint.parent_from_joint[:3, :3] @ joint.rotation(q[..., i])
            out = out @ step
        return out @ self.last_from_head


def paper_neck(d1_m: float, a2_m: float) -> SerialChain:
    """The paper's neck as a chain: yaw about W's z at the base, then pitch about x at height d1.

    Its ``world_from_head([theta1, theta2])`` is eq. (1): H sits a2 above the pitch axis.
    """
    yaw = RevoluteJoint(np.eye(4), np.array([0.0, 0.0, 1.0]), "yaw")
    pitch = RevoluteJoint(
        homogeneous(np.eye(3), np.array([0.0, 0.0, d1_m])), np.array([1.0, 0.0, 0.0]), "pitch"
    )
    return SerialChain(
        (yaw, pitch), homogeneous(_WORLD_FROM_HEAD_AT_ZERO, np.array([0.0, 0.0, a2_m]))
    )


def pitch_roll_yaw_neck(
    roll_from_pitch_m: Sequence[float],
    yaw_from_roll_m: Sequence[float],
    head_from_yaw_m: Sequence[float],
) -> SerialChain:
    """An iCub-like neck, ``world_from_head([pitch, roll, yaw])``.

    Pitch about W's x at W's origin (positive looks up), then roll about the pitched
    forward axis (positive tips the head's top towards +x, the right), then yaw about
    the rolled up axis (positive turns left, as eq. (1)'s theta1).  The offsets (3,),
    m, are each joint's (and H's) position relative to the previous one, in W's axes
    at the zero pose; there H has the axes of eq. (1) at theta = 0.
    """

    def at(offset: Sequence[float], name: str) -> np.ndarray:
        v = np.asarray(offset, float)
        if v.shape != (3,) or not np.isfinite(v).all():
            raise ValueError(f"{name} must be a finite offset (3,) in metres, got {offset!r}")
        return homogeneous(np.eye(3), v)

    joints = (
        RevoluteJoint(np.eye(4), np.array([1.0, 0.0, 0.0]), "pitch"),
        RevoluteJoint(
            at(roll_from_pitch_m, "roll_from_pitch_m"), np.array([0.0, 1.0, 0.0]), "roll"
        ),
        RevoluteJoint(at(yaw_from_roll_m, "yaw_from_roll_m"), np.array([0.0, 0.0, 1.0]), "yaw"),
    )
    last = at(head_from_yaw_m, "head_from_yaw_m")
    last[:3, :3] = _WORLD_FROM_HEAD_AT_ZERO
    return SerialChain(joints, last)


#: The two-joint necks headsim runs: eq. (1)'s yaw at the base, or pitch at the base.
NECK_ORDERS = ("yaw_pitch", "pitch_yaw")


@dataclass(frozen=True)
class Neck:
    """A neck of a yaw and a pitch joint, by which is at the base (H10).

    ``order``: ``"yaw_pitch"`` is eq. (1) (yaw about W's z at the base, pitch above it,
    H ``a2`` above the pitch axis, ``d1`` up); ``"pitch_yaw"`` pitches about W's x at
    W's origin, then yaws about the pitched z through ``(0, 0, d1)``, H ``a2`` above and
    ``forward_m`` ahead of that point: (H6) with its roll held at zero (the iCub's).
    Angles as eq. (1)'s: ``theta1`` yaw, positive turns left; ``theta2`` pitch, positive
    looks up.
    """

    order: str = "yaw_pitch"
    forward_m: float = 0.0

    def __post_init__(self) -> None:
        if self.order not in NECK_ORDERS:
            raise ValueError(f"order must be one of {', '.join(NECK_ORDERS)}, got {self.order!r}")
        if not math.isfinite(self.forward_m):
            raise ValueError(f"forward_m must be finite, got {self.forward_m!r}")
        if self.order == "yaw_pitch" and self.forward_m != 0.0:
            raise ValueError("forward_m is for a pitch_yaw neck; eq. (1) has H on the yaw axis")

    def world_from_head(
        self, theta1: ArrayLike, theta2: ArrayLike, d1: float, a2: float
    ) -> np.ndarray:
        """W_T_H (..., 4, 4); angles rad, broadcast; d1, a2 m."""
        if self.order == "yaw_pitch":
            return kinematics.world_from_head(theta1, theta2, d1, a2)
        t1, t2 = np.broadcast_arrays(np.asarray(theta1, float), np.asarray(theta2, float))
        c1, s1, c2, s2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
        zero, one = np.zeros_like(t1), np.ones_like(t1)
        # Rx(theta2) Rz(theta1) R0, and Rx(theta2) [(0, 0, d1) + Rz(theta1) (0, f, a2)].
        f, h = self.forward_m, d1 + a2
        px, py = -f * s1, f * c1
        rows = [
            [c1, zero, -s1, px],
            [c2 * s1, s2, c2 * c1, c2 * py - s2 * h],
            [s2 * s1, -c2, s2 * c1, s2 * py + c2 * h],
            [zero, zero, zero, one],
        ]
        return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)

    def head_to_world(
        self, points_h: ArrayLike, theta1: ArrayLike, theta2: ArrayLike, d1: float, a2: float
    ) -> np.ndarray:
        """Points (..., 3) from H to W."""
        if self.order == "yaw_pitch":
            return kinematics.head_to_world(points_h, theta1, theta2, d1, a2)
        p = points3(points_h, "points_h")
        t = self.world_from_head(theta1, theta2, d1, a2)
        return np.einsum("...ij,...j->...i", t[..., :3, :3], p) + t[..., :3, 3]

    def world_to_head(
        self, points_w: ArrayLike, theta1: ArrayLike, theta2: ArrayLike, d1: float, a2: float
    ) -> np.ndarray:
        """Points (..., 3) from W to H, the inverse of :meth:`head_to_world`."""
        if self.order == "yaw_pitch":
            return kinematics.world_to_head(points_w, theta1, theta2, d1, a2)
        p = points3(points_w, "points_w")
        t = self.world_from_head(theta1, theta2, d1, a2)
        return np.einsum("...ji,...j->...i", t[..., :3, :3], p - t[..., :3, 3])

    def as_chain(self, d1: float, a2: float) -> SerialChain:
        """The same neck as a :class:`SerialChain` of (yaw, pitch) or (pitch, yaw)."""
        if self.order == "yaw_pitch":
            return paper_neck(d1, a2)
        pitch = RevoluteJoint(np.eye(4), np.array([1.0, 0.0, 0.0]), "pitch")
        yaw = RevoluteJoint(
            homogeneous(np.eye(3), np.array([0.0, 0.0, d1])), np.array([0.0, 0.0, 1.0]), "yaw"
        )
        last = homogeneous(_WORLD_FROM_HEAD_AT_ZERO, np.array([0.0, self.forward_m, a2]))
        return SerialChain((pitch, yaw), last)


# --- version and vergence --------------------------------------------------------------


@dataclass(frozen=True)
class VersionVergence:
    """Version, rad (positive: both eyes turn towards +x of H, the right), and vergence, rad (total inward)."""

    version_rad: np.ndarray
    vergence_rad: np.ndarray


def version_vergence(inward1_rad: ArrayLike, inward2_rad: ArrayLike) -> VersionVergence:
    """Version (l - r) / 2 and vergence l + r of the inward pans l (Ca1, left) and r (Ca2), rad.

    Ca1's inward turn is towards +x and Ca2's towards -x, so the optical axes'
    azimuths towards +x are l and -r: version is their mean, vergence the angle between them.
    """
    left, right = np.broadcast_arrays(
        np.asarray(inward1_rad, float), np.asarray(inward2_rad, float)
    )
    return VersionVergence(0.5 * (left - right), left + right)


def inward_from_version_vergence(version_rad: ArrayLike, vergence_rad: ArrayLike) -> EyePans:
    """The inward pans, rad: l = vergence / 2 + version (Ca1), r = vergence / 2 - version (Ca2)."""
    ver, verg = np.broadcast_arrays(np.asarray(version_rad, float), np.asarray(vergence_rad, float))
    return EyePans(0.5 * verg + ver, 0.5 * verg - ver)


def fixation_point_from_version_vergence(
    version_rad: ArrayLike, vergence_rad: ArrayLike, baseline_m: float
) -> np.ndarray:
    """The fixated point (..., 3) in the eye frame, m, from true version psi and vergence gamma, rad.

    x = D sin(2 psi) / (2 sin gamma), y = 0, z = D (cos 2 psi + cos gamma) / (2 sin gamma):
    :func:`fixation_point_head` with l = gamma/2 + psi, r = gamma/2 - psi (no offsets);
    at psi = 0, z = D / (2 tan(gamma / 2)), eq. (2).  Raises ValueError unless
    0 < gamma < pi and both pans are within +-pi/2.
    """
    d = _baseline(baseline_m)
    pans = inward_from_version_vergence(version_rad, vergence_rad)
    psi = 0.5 * (pans.inward1_rad - pans.inward2_rad)
    gamma = pans.inward1_rad + pans.inward2_rad
    bad = ~(
        (gamma > 0.0)
        & (gamma < math.pi)
        & (np.abs(pans.inward1_rad) < _HALF_PI)
        & (np.abs(pans.inward2_rad) < _HALF_PI)
    )
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        raise ValueError(
            f"version_rad, vergence_rad must give 0 < vergence < pi and |inward pans| < pi/2; "
            f"{int(bad.sum())} do not, e.g. version {float(psi.ravel()[i])!r}, vergence {float(gamma.ravel()[i])!r}"
        )
    scale = d / (2.0 * np.sin(gamma))
    return np.stack(
        [
            scale * np.sin(2.0 * psi),
            np.zeros_like(psi),
            scale * (np.cos(2.0 * psi) + np.cos(gamma)),
        ],
        axis=-1,
    )


# --- eye axes ----------------------------------------------------------------------------


@dataclass(frozen=True)
class EyeAxesAlignment:
    """How far two eye pan axes are from the model's: parallel, and perpendicular to the baseline, rad.

    between_axes_rad: angle between the two axes as lines, [0, pi/2].
    axis1_off_perpendicular_rad, axis2_off_perpendicular_rad: each axis's angle from
    the plane perpendicular to the baseline, [0, pi/2].
    """

    between_axes_rad: float
    axis1_off_perpendicular_rad: float
    axis2_off_perpendicular_rad: float

    @property
    def worst_rad(self) -> float:
        """The largest of the three angles, rad."""
        return max(
            self.between_axes_rad,
            self.axis1_off_perpendicular_rad,
            self.axis2_off_perpendicular_rad,
        )

    def within(self, tolerance_rad: float) -> bool:
        """Whether all three angles are at most ``tolerance_rad``."""
        return self.worst_rad <= tolerance_rad


def eye_axes_alignment(
    axis1: ArrayLike, axis2: ArrayLike, baseline_direction: ArrayLike
) -> EyeAxesAlignment:
    """Angles of the eye pan axes (3,) against each other and the baseline direction (3,), one frame (H or W).

    Directions only, any length > 0; signs do not matter (lines).  Angles from
    atan2(|a x b|, |a . b|), accurate near 0 and pi/2.
    """
    a1, a2, b = (
        _direction(v, name)
        for v, name in (
            (axis1, "axis1"),
            (axis2, "axis2"),
            (baseline_direction, "baseline_direction"),
        )
    )

    def between(u: np.ndarray, v: np.ndarray) -> float:
        return math.atan2(float(np.linalg.norm(np.cross(u, v))), abs(float(u @ v)))

    def off_perpendicular(u: np.ndarray) -> float:
        return math.atan2(abs(float(u @ b)), float(np.linalg.norm(np.cross(u, b))))

    return EyeAxesAlignment(between(a1, a2), off_perpendicular(a1), off_perpendicular(a2))


def check_eye_axes(
    axis1: ArrayLike, axis2: ArrayLike, baseline_direction: ArrayLike, tolerance_rad: float
) -> EyeAxesAlignment:
    """:func:`eye_axes_alignment`, raising ValueError when an angle exceeds ``tolerance_rad``."""
    if not tolerance_rad >= 0.0:
        raise ValueError(f"tolerance_rad must be >= 0, got {tolerance_rad!r}")
    found = eye_axes_alignment(axis1, axis2, baseline_direction)
    problems = []
    if found.between_axes_rad > tolerance_rad:
        problems.append(f"eye axes not parallel: {found.between_axes_rad:.3g} rad apart")
    for i, off in ((1, found.axis1_off_perpendicular_rad), (2, found.axis2_off_perpendicular_rad)):
        if off > tolerance_rad:
            problems.append(f"eye axis {i} not perpendicular to the baseline: {off:.3g} rad off")
    if problems:
        raise ValueError("; ".join(problems) + f" (tolerance {tolerance_rad:.3g} rad)")
    return found


# --- helpers ------------------------------------------------------------------------------


def _raise_where(bad: np.ndarray, a1: np.ndarray, a2: np.ndarray, what: str) -> None:
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        raise ValueError(
            f"alpha1_rad, alpha2_rad with alpha_e_rad {what} (true yaws a_i = alpha_i + alpha_ei) "
            f"for {int(bad.sum())} of {bad.size}, e.g. a1 = {float(a1.ravel()[i])!r}, "
            f"a2 = {float(a2.ravel()[i])!r}"
        )


def _baseline(baseline_m: float) -> float:
    d = float(baseline_m)
    if not (math.isfinite(d) and 0.0 < d < 10.0):
        raise ValueError(f"baseline_m must be in metres, 0 < D < 10, got {baseline_m!r}")
    return d


def _pair(values: tuple[float, float], name: str) -> tuple[float, float]:
    a, b = (float(v) for v in values)
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ValueError(f"{name} must be two finite numbers, got {values!r}")
    return a, b


def _direction(v: ArrayLike, name: str) -> np.ndarray:
    u = np.asarray(v, dtype=float)
    norm = float(np.linalg.norm(u)) if u.shape == (3,) else math.nan
    if not (math.isfinite(norm) and norm > 0.0):
        raise ValueError(f"{name} must be a non-zero finite vector (3,), got {v!r}")
    return u / norm


def _is_rigid(pose: np.ndarray) -> bool:
    r = pose[:3, :3]
    return bool(
        np.isfinite(pose).all()
        and np.allclose(r @ r.T, np.eye(3), atol=1e-9)
        and np.linalg.det(r) > 0.0
        and np.allclose(pose[3], [0.0, 0.0, 0.0, 1.0])
    )
