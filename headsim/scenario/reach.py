"""Reach: can the head see and fixate a point from its start pose?  Geometry only, no rendering.

Model 2 needs each eye's fixation angle within the eye range and the point
seen whole by both cameras at the start pose; Model 1 needs the neck's and
the eye's angles within their ranges (and, for a first position, the same
start-pose view).  :func:`reach_refusal` is the check scripts use; the
scenario loader refuses every target, corner, object and path point that
fails it, naming why.  Points in W or H, m; angles rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache, lru_cache

import mujoco
import numpy as np

from headsim.geometry.kinematics import world_to_head
from headsim.scenario.spec import (
    CHESSBOARD_PATTERN,
    CHESSBOARD_SQUARE_M,
    MAX_DEPTH_M,
    MIN_DEPTH_M,
    Placement,
    Scenario,
    corner_count,
)
from headsim.scenario.tables import Context
from headsim.sim import names
from headsim.sim.forward import effective_directions
from headsim.sim.model import eye_from_camera_rotation, load_spec
from headsim.sim.settings import HeadSettings


@cache
def scene_model(scene: str) -> mujoco.MjModel:
    """The compiled scene as in the XML (joint ranges, default poses); no rendering."""
    return load_spec(scene).compile()


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
        model = scene_model("base")

        def rng(joint: str) -> tuple[float, float]:
            lo, hi = model.joint(joint).range
            return float(lo), float(hi)

        directions = effective_directions(settings)
        return cls(
            settings,
            rng(names.EYE_MOTOR_JOINT),
            rng(names.NECK_YAW),
            rng(names.NECK_PITCH),
            directions,
        )

    def effective_direction(self, index: int) -> float:
        """Camera ``index``'s image-centre ray off the head's forward axis at eye 0, rad."""
        return self.directions[index]

    def in_view(
        self, point_head: np.ndarray, index: int, eye: float = 0.0, radius_m: float = 0.0
    ) -> bool:
        """Whether a point projects into camera ``index``'s image at eye angle ``eye``.

        With ``radius_m``, a ball of that radius around it images whole: its
        centre's image is its apparent radius plus 2 px inside the border (what
        the detector needs not to call it cut).
        """
        camera = self.settings.cameras[index]
        sign = names.EYE_CAMERAS[index].inward
        centre = np.array([sign * -self.settings.baseline_m / 2, 0.0, 0.0])
        c, s = math.cos(sign * eye), math.sin(sign * eye)
        eye_rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        rotation = eye_rotation @ eye_from_camera_rotation(camera, index)
        p = rotation.T @ (point_head - centre)
        if p[2] <= 0.01:
            return False
        u, v = camera.pinhole().project(p)  # NaN beyond where the lens folds over
        m = 2.0 + max(camera.kx, camera.ky) * radius_m / p[2] if radius_m > 0 else 0.0
        return bool(m <= u <= camera.width - 1 - m and m <= v <= camera.height - 1 - m)

    def model2_angles(self, p: np.ndarray) -> tuple[float, float]:
        """Encoder readings alpha1, alpha2 at which each camera fixates ``p`` (H), rad."""
        half = self.settings.baseline_m / 2
        alpha1 = math.atan2(p[0] + half, p[2]) - self.effective_direction(0)
        alpha2 = math.atan2(half - p[0], p[2]) - self.effective_direction(1)
        return alpha1, alpha2

    def to_head(self, point_world: np.ndarray) -> np.ndarray:
        s = self.settings
        return world_to_head(point_world, 0.0, 0.0, s.neck_d1_m, s.neck_a2_m)


def _fmt(p: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.3f}" for v in p) + "]"


def _check_in_front(ctx: Context, source: str, p_head: np.ndarray, what: str) -> None:
    if not MIN_DEPTH_M <= p_head[2] <= MAX_DEPTH_M:
        where = "behind or too close to the head" if p_head[2] < MIN_DEPTH_M else "too far"
        raise ctx.error(
            source,
            f"{what} at {_fmt(p_head)} m in H is {where}",
            f"z_h from {MIN_DEPTH_M:g} to {MAX_DEPTH_M:g} m in front of the head",
        )


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
    head: ReachHead, p_world: np.ndarray, what: str, radius_m: float = 0.0
) -> tuple[str, str] | None:
    """Why Model 2 cannot measure a point (message, what is allowed), or None: it can.

    The criterion the procedure meets (``headsim.active.model2.measure_model2``
    searches the start pose when a camera loses the target): in front of the
    head, each camera's fixation angle within the eye range, and the target
    seen whole by both cameras at the start pose (neck and eyes at 0).
    """
    p = head.to_head(p_world)
    if not MIN_DEPTH_M <= p[2] <= MAX_DEPTH_M:
        where = "behind or too close to the head" if p[2] < MIN_DEPTH_M else "too far"
        return (
            f"{what} at {_fmt(p)} m in H is {where}",
            f"z_h from {MIN_DEPTH_M:g} to {MAX_DEPTH_M:g} m in front of the head",
        )
    lo, hi = head.eye_range
    for camera, alpha in enumerate(head.model2_angles(p), start=1):
        if not lo <= alpha <= hi:
            return (
                f"{what} at {_fmt(p)} m in H needs an eye angle of {alpha:.3f} rad for "
                f"camera {camera} to fixate it",
                f"targets that both eyes fixate within the eye range [{lo:g}, {hi:g}] rad",
            )
    for index in (0, 1):
        if not head.in_view(p, index, 0.0, radius_m):
            return (
                f"{what} at {_fmt(p)} m in H is not seen whole by camera {index + 1} at the "
                "start pose",
                "a target that both cameras see whole with neck and eyes at 0",
            )
    return None


def _check_model2_reach(
    ctx: Context,
    head: ReachHead,
    source: str,
    p_world: np.ndarray,
    what: str,
    radius_m: float = 0.0,
) -> None:
    """Refuse a point that :func:`model2_refusal` refuses, naming the reason."""
    refusal = model2_refusal(head, p_world, what, radius_m)
    if refusal is not None:
        raise ctx.error(source, *refusal)


def _model1_angles(head: ReachHead, p_world: np.ndarray) -> tuple[float, float, float]:
    """Neck yaw, neck pitch and eye angle that fixate a world point with Model 1, rad."""
    s = head.settings
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
    head: ReachHead, p_world: np.ndarray, what: str, start: bool, radius_m: float = 0.0
) -> tuple[str, str] | None:
    """Why Model 1 cannot fixate a point (message, what is allowed), or None: it can.

    Within the neck's and eye's ranges; if ``start`` (a first position, which the
    procedure looks for at the start pose), in front and seen whole by both
    cameras with neck and eyes at 0.
    """
    p = head.to_head(p_world)
    yaw, pitch, eye = _model1_angles(head, p_world)
    if math.isnan(pitch):
        s = head.settings
        distance = math.hypot(math.hypot(p_world[0], p_world[1]), p_world[2] - s.neck_d1_m)
        return (
            f"{what} at {_fmt(np.asarray(p_world))} m in W is {distance:.3f} m from the neck's "
            f"pitch axis, inside the eyes' offset from it (head.neck_a2_m = {s.neck_a2_m:g} m): "
            "no neck pitch turns the eyes towards it",
            "targets farther from the neck's pitch axis than head.neck_a2_m",
        )
    ranges = (
        ("neck yaw", yaw, head.neck_yaw_range),
        ("neck pitch", pitch, head.neck_pitch_range),
        ("eye angle", eye, head.eye_range),
    )
    for label, angle, (lo, hi) in ranges:
        if not lo <= angle <= hi:
            return (
                f"{what} at {_fmt(np.asarray(p_world))} m in W needs a {label} of {angle:.3f} rad",
                f"targets the neck and eyes fixate within their ranges: neck yaw "
                f"[{head.neck_yaw_range[0]:g}, {head.neck_yaw_range[1]:g}], neck pitch "
                f"[{head.neck_pitch_range[0]:g}, {head.neck_pitch_range[1]:g}], eyes "
                f"[{head.eye_range[0]:g}, {head.eye_range[1]:g}] rad",
            )
    if start:
        if not MIN_DEPTH_M <= p[2] <= MAX_DEPTH_M:
            where = "behind or too close to the head" if p[2] < MIN_DEPTH_M else "too far"
            return (
                f"{what} at {_fmt(p)} m in H is {where}",
                f"z_h from {MIN_DEPTH_M:g} to {MAX_DEPTH_M:g} m in front of the head",
            )
        for index in (0, 1):
            if not head.in_view(p, index, 0.0, radius_m):
                return (
                    f"{what} at {_fmt(p)} m in H is not seen whole by camera {index + 1} at "
                    "the start pose",
                    "a first position that both cameras see whole with neck and eyes at 0",
                )
    return None


@lru_cache(maxsize=8)
def _head_of(settings: HeadSettings) -> ReachHead:
    return ReachHead.of(settings)


def reach_refusal(
    settings: HeadSettings,
    p_world: np.ndarray,
    what: str = "target",
    radius_m: float = 0.0,
) -> tuple[str, str] | None:
    """The scenario's reach check for one first target, for Model 2 and Model 1 alike.

    (message, what is allowed) from the first model that refuses the world
    point ``p_world``, m, or None: both procedures can measure it from the
    start pose.  The same criterion ``within = "reach"`` applies.
    """
    head = _head_of(settings)
    return model2_refusal(head, p_world, what, radius_m) or model1_refusal(
        head, p_world, what, True, radius_m
    )


def _check_model1_reach(
    ctx: Context,
    head: ReachHead,
    source: str,
    p_world: np.ndarray,
    what: str,
    start: bool,
    radius_m: float = 0.0,
) -> None:
    """Refuse a point that :func:`model1_refusal` refuses, naming the reason."""
    refusal = model1_refusal(head, p_world, what, start, radius_m)
    if refusal is not None:
        raise ctx.error(source, *refusal)


def _chessboard_corners_world(placement: Placement, corners: tuple[int, ...] | None) -> np.ndarray:
    """World positions of the chosen inner corners of a board placed at ``placement``."""
    model = scene_model("chessboard")
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.body(names.CHESSBOARD).quat)
    columns = CHESSBOARD_PATTERN[0]
    indices = range(corner_count()) if corners is None else corners
    local = np.array(
        [
            [(k % columns) * CHESSBOARD_SQUARE_M, (k // columns) * CHESSBOARD_SQUARE_M, 0.0]
            for k in indices
        ]
    )
    return np.asarray(placement.position_world_m) + local @ rotation.reshape(3, 3).T


def check_reach(ctx: Context, scenario: Scenario) -> None:
    head = ReachHead.of(scenario.settings)
    scene = scenario.scene
    procedure = scenario.experiment.procedure
    for target in scene.targets:
        radius = body_radius(target.body)
        if procedure == "model1":
            _check_model1_reach(
                ctx,
                head,
                f"{target.source}",
                np.array(target.position_world_m),
                "target",
                True,
                radius,
            )
        else:
            _check_model2_reach(
                ctx, head, target.source, np.array(target.position_world_m), "target", radius
            )
    if scene.chessboard is not None:
        indices = range(corner_count()) if scene.corners is None else scene.corners
        for k, p in zip(
            indices, _chessboard_corners_world(scene.chessboard, scene.corners), strict=True
        ):
            _check_model2_reach(ctx, head, scene.chessboard.source, p, f"corner {k}")
    if scene.blocks is not None:
        _check_model2_reach(
            ctx, head, scene.blocks.source, np.array(scene.blocks.position_world_m), "cross point"
        )
        for placement in scene.objects:
            p = head.to_head(np.array(placement.position_world_m))
            _check_in_front(ctx, placement.source, p, placement.name)
            if not (head.in_view(p, 0) and head.in_view(p, 1)):
                raise ctx.error(
                    placement.source,
                    f"{placement.name} at {_fmt(p)} m in H is outside a camera's view at the start pose",
                    "objects that both cameras see with neck and eyes at 0",
                )
    if scene.pursuit is not None:
        pursuit = scene.pursuit
        first = True
        for t in pursuit.sample_times():
            if not pursuit.visibility.visible(float(t)):
                continue
            _check_model1_reach(
                ctx,
                head,
                "scene.pursuit.path",
                pursuit.path.position(float(t)),
                f"the target at t = {t:g} s",
                first,
            )
            first = False
    if scene.moving is not None:
        moving = scene.moving
        for k, t in enumerate(moving.times_s):
            _check_model1_reach(
                ctx,
                head,
                "scene.moving_target",
                moving.position(float(t)),
                f"the target at t = {t:g} s",
                k == 0,
                body_radius(moving.body),
            )
