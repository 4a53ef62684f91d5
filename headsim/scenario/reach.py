"""Reach: can the head fixate a point at all?  Geometry only, no rendering.

A target is refused only where no pose the procedure may take fixates it:
Model 2 (the neck still, as in the paper) needs it in front (z_h 0.1-10 m),
each camera's fixation angle within the eye range, each camera seeing it
whole where it fixates it, and nothing of the scene in either camera's line
of sight (from its entrance pupil, at the start pose and where it fixates:
:meth:`ReachHead.optical_centre`); Model 1 needs the neck's and the eye's fixation angles within
their ranges, the same depth and lines of sight, and both cameras seeing it
whole from some neck pose with the eyes at 0 (where its neck servo can
start).  A target that the start pose does not show is not refused: the
procedures scan for it (``headsim.active.search.scan_eyes``/``scan_neck``).
A moving target's first position, a chessboard corner and the blocks' cross
point are still refused outside the start pose's view (those procedures
start there).  Every refusal is a :class:`Refusal` with a short reason code
(:data:`headsim.scenario.spec.REFUSAL_REASONS`).  :func:`reach_refusal` is
the check scripts use; the scenario loader refuses every listed target,
corner, object and path point that fails it, naming why, and counts the
random draws it refuses.  Points in W or H, m; angles rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from headsim.geometry.camera_model import PinholeCamera
from headsim.geometry.kinematics import eye_from_camera_rotation
from headsim.scenario.occlusion import Occluder, hidden_by, scene_model, scene_occluders
from headsim.scenario.spec import (
    MAX_DEPTH_M,
    MIN_DEPTH_M,
)
from headsim.sim import names
from headsim.sim.forward import effective_directions
from headsim.sim.heads import eye_motor_range
from headsim.sim.model import head_names, neck_of
from headsim.sim.settings import CameraSettings, HeadSettings


@lru_cache(maxsize=16)
def _pinhole(camera: CameraSettings) -> PinholeCamera:
    """A camera's lens, made once (the loader asks for it at every point it checks)."""
    return camera.pinhole()


@lru_cache(maxsize=16)
def _mount_rotation(camera: CameraSettings, sign: float) -> np.ndarray:
    """:func:`eye_from_camera_rotation` of a camera's mount, made once."""
    return eye_from_camera_rotation(
        sign, camera.mount_yaw_rad, camera.mount_pitch_rad, camera.mount_roll_rad
    )


def _project(lens: PinholeCamera, p: np.ndarray) -> tuple[float, float] | None:
    """:meth:`PinholeCamera.project` of one point in floats (the loader asks at every
    point); None beyond where the lens folds over (not imaged)."""
    x, y = float(p[0] / p[2]), float(p[1] / p[2])
    if lens.is_distorted:
        r2 = x * x + y * y
        if r2 >= lens.fold_radius**2:
            return None
        scale = 1.0 + lens.k1 * r2 + lens.k2 * r2 * r2
        x, y = x * scale, y * scale
    return lens.kx * x + lens.cx, lens.ky * y + lens.cy


@dataclass(frozen=True)
class ReachHead:
    """The head at its start pose: cameras' poses in H, joint ranges, effective directions."""

    settings: HeadSettings
    eye_range: tuple[float, float]
    neck_yaw_range: tuple[float, float]
    neck_pitch_range: tuple[float, float]
    #: Each camera's effective direction (mount yaw and image-centre ray), computed once.
    directions: tuple[float, float]

    @classmethod
    def of(cls, settings: HeadSettings) -> ReachHead:
        model = scene_model("base", settings.head)
        mapping = head_names(settings.head)

        def rng(joint: str) -> tuple[float, float]:
            lo, hi = model.joint(joint).range
            return float(lo), float(hi)

        directions = effective_directions(settings)
        return cls(
            settings,
            eye_motor_range(model, mapping),
            rng(mapping.neck_yaw) if mapping.neck_yaw is not None else (0.0, 0.0),
            rng(mapping.neck_pitch),
            directions,
        )

    def effective_direction(self, index: int) -> float:
        """Camera ``index``'s image-centre ray off the head's forward axis at eye 0, rad."""
        return self.directions[index]

    def in_view(
        self, point_head: np.ndarray, index: int, eye: float = 0.0, radius_m: float = 0.0
    ) -> bool:
        """Whether a point projects into camera ``index``'s image at eye angle ``eye``.

        Seen from the camera's optical centre (off the yaw axis by the lens's offsets).
        With ``radius_m``, a ball of that radius around it images whole: its rim's
        image, through the lens, 2 px inside the border (what the detector needs
        not to call it cut).
        """
        camera = self.settings.cameras[index]
        sign = names.EYE_CAMERAS[index].inward
        c, s = math.cos(sign * eye), math.sin(sign * eye)
        eye_rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        rotation = eye_rotation @ _mount_rotation(camera, sign)
        p = rotation.T @ (point_head - self.optical_centre_head(index, eye))
        if p[2] <= 0.01:
            return False
        points = [p]
        if radius_m > 0:  # the ball's rim across the line of sight, through the lens
            sight = p / np.linalg.norm(p)
            across = np.cross(sight, [1.0, 0.0, 0.0])
            across /= np.linalg.norm(across)
            for d in (across, np.cross(across, sight)):
                points += [p + radius_m * d, p - radius_m * d]
        lens = _pinhole(camera)
        m = 2.0 if radius_m > 0 else 0.0
        for q in points:
            uv = _project(lens, q)
            if uv is None:
                return False
            u, v = uv
            if not (m <= u <= camera.width - 1 - m and m <= v <= camera.height - 1 - m):
                return False
        return True

    def model2_angles(self, p: np.ndarray) -> tuple[float, float]:
        """Encoder readings alpha1, alpha2 at which each camera fixates ``p`` (H), rad."""
        half = self.settings.baseline_m / 2
        alpha1 = math.atan2(p[0] + half, p[2]) - self.effective_direction(0)
        alpha2 = math.atan2(half - p[0], p[2]) - self.effective_direction(1)
        return alpha1, alpha2

    def to_head(self, point_world: np.ndarray, yaw: float = 0.0, pitch: float = 0.0) -> np.ndarray:
        """A world point in H with the neck at (``yaw``, ``pitch``), rad (default: the start pose)."""
        s = self.settings
        return neck_of(s.head).world_to_head(point_world, yaw, pitch, s.neck_d1_m, s.neck_a2_m)

    def optical_centre(
        self, index: int, eye: float = 0.0, yaw: float = 0.0, pitch: float = 0.0
    ) -> np.ndarray:
        """Camera ``index``'s true optical centre (its entrance pupil) in W, m, with its eye
        at ``eye`` (rad, as the encoder reads) and the neck at (``yaw``, ``pitch``).

        The true one, where the renderer draws from: the occlusion check asks what
        the images will show, and placement may use the truth.  On a real head the
        pupil sits ``nodal_offset_m`` ahead of the eye's yaw axis (20 mm on the
        realistic preset) and turns with the eye: from the axis alone, a marker
        that half hides another from the pupil passes.  The eye axis's tilt (mrad)
        is left out: it moves the pupil by hundredths of a millimetre.
        """
        s = self.settings
        centre_head = self.optical_centre_head(index, eye)
        return neck_of(s.head).head_to_world(centre_head, yaw, pitch, s.neck_d1_m, s.neck_a2_m)

    def optical_centre_head(self, index: int, eye: float = 0.0) -> np.ndarray:
        """Camera ``index``'s true optical centre in H with its eye at ``eye``, rad, m."""
        s, camera = self.settings, self.settings.cameras[index]
        sign = names.EYE_CAMERAS[index].inward
        # The mount's rotation applied to the offset, then the eye's about H's y.
        offset = _mount_rotation(camera, sign) @ np.array(
            [camera.side_offset_m, 0.0, camera.nodal_offset_m]
        )
        c, sn = math.cos(sign * eye), math.sin(sign * eye)
        return np.array(
            [
                -sign * s.baseline_m / 2 + c * offset[0] + sn * offset[2],
                offset[1],
                -sn * offset[0] + c * offset[2],
            ]
        )

    def in_start_view(self, point_world: np.ndarray, radius_m: float = 0.0) -> bool:
        """Whether both cameras see a world point whole at the start pose (neck and eyes at 0)."""
        p = self.to_head(point_world)
        return all(self.in_view(p, index, 0.0, radius_m) for index in (0, 1))


@dataclass(frozen=True)
class Refusal:
    """Why the head cannot fixate a point: a reason code, what is wrong and what is allowed.

    ``code``: one of :data:`headsim.scenario.spec.REFUSAL_REASONS` (results.json
    counts refused draws by it); ``message`` and ``allowed`` name the point and
    the rule, as the loader's error does.
    """

    code: str
    message: str
    allowed: str


def _occlusion(
    head: ReachHead,
    p_world: np.ndarray,
    what: str,
    radius_m: float,
    occluders: tuple[Occluder, ...],
    poses: tuple[tuple[float, float, float], ...],
) -> Refusal | None:
    """A refusal if the scene hides (any of) the point from either camera's optical centre
    at any of ``poses`` (neck yaw, neck pitch, eye angle; rad) where that camera sees it.

    The poses are where the procedure looks at the point: the start and the fixations.
    A partly hidden marker's centroid is biased, and the detector calls it occluded.
    """
    s = head.settings
    neck = neck_of(s.head)
    for yaw, pitch in dict.fromkeys((yaw, pitch) for yaw, pitch, _ in poses):
        at = [(index, eye) for y, p, eye in poses if (y, p) == (yaw, pitch) for index in (0, 1)]
        centres = neck.head_to_world(
            np.array([head.optical_centre_head(index, eye) for index, eye in at]),
            yaw,
            pitch,
            s.neck_d1_m,
            s.neck_a2_m,
        )
        for (index, eye), centre in zip(at, centres, strict=True):
            # 2 px of the true lens beside the ball (placement: truth allowed)
            margin = 2.0 / s.cameras[index].kx
            name = hidden_by(centre, p_world, radius_m, margin, occluders)
            # Hidden where the camera sees it (else there is nothing to hide).
            if name is not None and head.in_view(head.to_head(p_world, yaw, pitch), index, eye):
                return Refusal(
                    "occluded",
                    f"{what} at {fmt_point(head.to_head(p_world))} m in H is hidden from camera "
                    f"{index + 1} by {name}",
                    "targets that both cameras see with nothing of the scene in front of them",
                )
    return None


def fmt_point(p: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.3f}" for v in p) + "]"


def depth_refusal(p_head: np.ndarray, what: str) -> Refusal | None:
    """A refusal if a point in H (start pose) is behind, too near or too far, else None."""
    if MIN_DEPTH_M <= p_head[2] <= MAX_DEPTH_M:
        return None
    where = "behind or too close to the head" if p_head[2] < MIN_DEPTH_M else "too far"
    return Refusal(
        "depth",
        f"{what} at {fmt_point(p_head)} m in H is {where}",
        f"z_h from {MIN_DEPTH_M:g} to {MAX_DEPTH_M:g} m in front of the head",
    )


def _start_view_refusal(
    head: ReachHead, p: np.ndarray, what: str, radius_m: float, allowed: str
) -> Refusal | None:
    for index in (0, 1):
        if not head.in_view(p, index, 0.0, radius_m):
            return Refusal(
                "start_view",
                f"{what} at {fmt_point(p)} m in H is not seen whole by camera {index + 1} at the "
                "start pose",
                allowed,
            )
    return None


def body_radius(body: str | None) -> float:
    """A marker body's sphere radius, m (0 for other bodies)."""
    if body is None:
        return 0.0
    model = scene_model("default")
    try:
        geom = model.geom(body)
    except KeyError:
        return 0.0
    return float(geom.size[0])


def model2_refusal(
    head: ReachHead,
    p_world: np.ndarray,
    what: str,
    radius_m: float = 0.0,
    occluders: tuple[Occluder, ...] = (),
    start_view: bool = False,
) -> Refusal | None:
    """Why Model 2 cannot measure a point, or None: it can.

    The criterion the procedure meets with the neck still
    (``headsim.active.model2.measure_model2`` scans the eye range for a target
    camera 1 does not see, and searches for one camera 2 does not see): in
    front of the head, each camera's fixation angle within the eye range, each
    camera seeing it whole at its fixation angle (where it is nearest the
    image's middle row: no eye angle shows it whole if that one does not), and
    no geom of ``occluders`` in either line of sight.  ``start_view``: also
    seen whole by both cameras at the start pose (a chessboard corner, the
    blocks' cross point: those procedures start there).
    """
    p = head.to_head(p_world)
    refusal = depth_refusal(p, what)
    if refusal is not None:
        return refusal
    lo, hi = head.eye_range
    angles = head.model2_angles(p)
    for camera, alpha in enumerate(angles, start=1):
        if not lo <= alpha <= hi:
            return Refusal(
                "eye_range",
                f"{what} at {fmt_point(p)} m in H needs an eye angle of {alpha:.3f} rad for "
                f"camera {camera} to fixate it",
                f"targets that both eyes fixate within the eye range [{lo:g}, {hi:g}] rad",
            )
    if start_view:
        return _start_view_refusal(
            head, p, what, radius_m, "a target that both cameras see whole with neck and eyes at 0"
        )
    for index, alpha in enumerate(angles):
        if not head.in_view(p, index, alpha, radius_m):
            return Refusal(
                "not_in_any_view",
                f"{what} at {fmt_point(p)} m in H is not seen whole by camera {index + 1} even where "
                f"it fixates it (eye angle {alpha:.3f} rad): it lies above or below that view",
                "targets that each camera sees whole at some eye angle with the neck still",
            )
    # The start pose, then each camera's fixation (the eyes move together on a coupled head).
    poses = tuple((0.0, 0.0, eye) for eye in (0.0, *angles))
    return _occlusion(head, p_world, what, radius_m, occluders, poses)


def _model1_angles(head: ReachHead, p_world: np.ndarray) -> tuple[float, float, float]:
    """Neck yaw, neck pitch and eye angle that fixate a world point with Model 1, rad."""
    s = head.settings
    neck = neck_of(s.head)
    if neck.order == "pitch_yaw":  # (H10): pitch brings the point to H's height, yaw ahead
        height = s.neck_d1_m + s.neck_a2_m
        rho = math.hypot(p_world[1], p_world[2])
        if rho <= height:
            return math.nan, math.nan, math.nan
        pitch = math.atan2(p_world[2], p_world[1]) - math.asin(height / rho)
        ahead = math.cos(pitch) * p_world[1] + math.sin(pitch) * p_world[2]
        yaw = math.atan2(-p_world[0], ahead)
        depth = math.hypot(p_world[0], ahead) - neck.forward_m
    else:
        yaw = math.atan2(-p_world[0], p_world[1])
        rho, height = math.hypot(p_world[0], p_world[1]), p_world[2] - s.neck_d1_m
        reach = math.hypot(rho, height)
        if reach <= s.neck_a2_m:
            return yaw, math.nan, math.nan
        pitch = math.atan2(height, rho) - math.asin(s.neck_a2_m / reach)
        depth = math.sqrt(max(reach**2 - s.neck_a2_m**2, 0.0))
    eye = math.atan2(s.baseline_m / 2, depth) - 0.5 * (
        head.effective_direction(0) + head.effective_direction(1)
    )
    return yaw, pitch, eye


def model1_refusal(
    head: ReachHead,
    p_world: np.ndarray,
    what: str,
    start: bool,
    radius_m: float = 0.0,
    occluders: tuple[Occluder, ...] = (),
    start_view: bool = True,
) -> Refusal | None:
    """Why Model 1 cannot fixate a point, or None: it can.

    Within the neck's and eye's ranges.  If ``start`` (a first position, which the
    procedure looks for from the start pose): in front; then, with ``start_view``
    (a moving target, tracked from where the start pose sees it), seen whole by
    both cameras with neck and eyes at 0; without it (a target, which
    ``headsim.active.model1.measure_model1`` scans the neck for), seen whole by
    both cameras from the neck pose that fixates it with the eyes at 0 (where
    the neck scan can find it and the servo start: the eyes converge only
    then), and no geom of ``occluders`` in either line of sight there.
    """
    p = head.to_head(p_world)
    yaw, pitch, eye = _model1_angles(head, p_world)
    if math.isnan(pitch):
        s = head.settings
        distance = math.hypot(math.hypot(p_world[0], p_world[1]), p_world[2] - s.neck_d1_m)
        return Refusal(
            "neck_offset",
            f"{what} at {fmt_point(np.asarray(p_world))} m in W is {distance:.3f} m from the neck's "
            f"pitch axis, inside the eyes' offset from it (head.neck_a2_m = {s.neck_a2_m:g} m): "
            "no neck pitch turns the eyes towards it",
            "targets farther from the neck's pitch axis than head.neck_a2_m",
        )
    ranges = (
        ("neck_range", "neck yaw", yaw, head.neck_yaw_range),
        ("neck_range", "neck pitch", pitch, head.neck_pitch_range),
        ("eye_range", "eye angle", eye, head.eye_range),
    )
    for code, label, angle, (lo, hi) in ranges:
        if not lo <= angle <= hi:
            return Refusal(
                code,
                f"{what} at {fmt_point(np.asarray(p_world))} m in W needs a {label} of {angle:.3f} rad",
                f"targets the neck and eyes fixate within their ranges: neck yaw "
                f"[{head.neck_yaw_range[0]:g}, {head.neck_yaw_range[1]:g}], neck pitch "
                f"[{head.neck_pitch_range[0]:g}, {head.neck_pitch_range[1]:g}], eyes "
                f"[{head.eye_range[0]:g}, {head.eye_range[1]:g}] rad",
            )
    if not start:
        return None
    refusal = depth_refusal(p, what)
    if refusal is not None:
        return refusal
    if start_view:
        return _start_view_refusal(
            head,
            p,
            what,
            radius_m,
            "a first position that both cameras see whole with neck and eyes at 0",
        )
    facing = head.to_head(p_world, yaw, pitch)
    for index in (0, 1):
        if not head.in_view(facing, index, 0.0, radius_m):
            return Refusal(
                "not_in_any_view",
                f"{what} at {fmt_point(np.asarray(p_world))} m in W is not seen whole by camera "
                f"{index + 1} with the neck turned to face it (yaw {yaw:.3f}, pitch "
                f"{pitch:.3f} rad) and the eyes at 0: too near for both views",
                "targets that both cameras see whole from some neck pose with the eyes at 0 "
                "(Model 1 scans the neck; its servo converges the eyes once both see it)",
            )
    # The start pose, the neck facing it with the eyes at 0 (where the servo starts), fixated.
    poses = ((0.0, 0.0, 0.0), (yaw, pitch, 0.0), (yaw, pitch, eye))
    return _occlusion(head, p_world, what, radius_m, occluders, poses)


#: The reach check's head for settings, made once per head.
_head_of = lru_cache(maxsize=8)(ReachHead.of)


def target_refusal(
    head: ReachHead,
    reach: str,
    p_world: np.ndarray,
    what: str = "target",
    radius_m: float = 0.0,
    occluders: tuple[Occluder, ...] = (),
) -> Refusal | None:
    """The reach check of one target that ``reach`` measures ("model1": the neck turns too;
    else Model 2, the eyes from the start pose): a procedure's ``Procedure.reach``."""
    if reach == "model1":
        return model1_refusal(head, p_world, what, True, radius_m, occluders, start_view=False)
    return model2_refusal(head, p_world, what, radius_m, occluders)


def reach_refusal(
    settings: HeadSettings,
    p_world: np.ndarray,
    what: str = "target",
    radius_m: float = 0.0,
    body: str | None = None,
) -> Refusal | None:
    """The scenario's reach check for one target, for Model 2 and Model 1 alike.

    The :class:`Refusal` of the first model that refuses the world point
    ``p_world``, m, or None: both procedures can measure it (from the start
    pose, or after a scan).  ``body``: the marker placed there (its own place in
    the default scene then hides nothing); the other geoms of the default scene
    stay where its XML puts them.  The criterion ``within = "reach"`` applies.
    """
    head = _head_of(settings)
    occluders = scene_occluders("default", None, body)
    return model2_refusal(head, p_world, what, radius_m, occluders) or model1_refusal(
        head, p_world, what, True, radius_m, occluders, start_view=False
    )


__all__ = [
    "Occluder",
    "ReachHead",
    "Refusal",
    "body_radius",
    "depth_refusal",
    "fmt_point",
    "model1_refusal",
    "model2_refusal",
    "reach_refusal",
    "scene_model",
    "scene_occluders",
    "target_refusal",
]
