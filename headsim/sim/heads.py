"""Heads as data: a head's MJCF file and the mapping that names its joints and cameras.

A scenario names its head as a shipped one (:data:`REGISTRY`: ``paper``, and each
file in models/ that declares its description and mapping in its ``<custom>`` block)
or as a user's MJCF file with a :class:`HeadMapping`.  The
simulator takes every joint, body and camera name from the mapping, and the head's
true kinematics from the compiled model.  :func:`check_head` holds a mapping
against the model and says, naming the mapping's key, what the method needs
(docs/equations.md, "Beyond the paper: other heads").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from headsim.errors import BadInput
from headsim.geometry.heads import Neck
from headsim.sim import names
from headsim.sim.declared import Array, Choice, Section, Text
from headsim.sim.head_files import DECLARATION, DECLARED, MODELS_DIR, SHIPPED

#: How a head drives its two eye pan joints.
EYE_KINDS = ("coupled", "independent", "version_vergence")
#: Largest angle between the two eye pan axes, or of one axis from perpendicular to
#: the baseline, that the measurement equations tolerate, rad (about 0.06 degrees:
#: a 1 mm target error at 1 m; real heads are built to this or calibrated).
AXIS_TOLERANCE_RAD = 1e-3
#: Largest offset of a neck axis from eq. (1)'s chain, m.
NECK_TOLERANCE_M = 1e-6
#: Smallest side of an eye camera's image, pixels.
MIN_CAMERA_SIDE_PX = 32


class HeadError(BadInput, ValueError):
    """A head mapping does not fit its model, or the model not the method; names the key."""

    def __init__(self, key: str, problem: str, allowed: str) -> None:
        super().__init__(f"head.mapping.{key}: {problem} (allowed: {allowed})")
        self.key, self.problem, self.allowed = key, problem, allowed


def _part(key: str, kind: str, meaning: str, *, optional: bool = False) -> Text:
    """A mapping key that names a ``kind`` (joint, body, actuator) of the head's MJCF file."""
    what = f"the name of a {kind} in the head's MJCF file" + (" (or leave it out)" * optional)
    return Text(key, None, meaning, what=what, required=not optional)


#: ``[head.mapping]``: the names a user's MJCF head declares, one key per
#: :class:`HeadMapping` field, in the order the loader reads them.
CAMERAS = Array(
    "cameras", "an array of two camera names [left (Ca1), right (Ca2)]",
    "The two eye cameras, [Ca1, Ca2]: left, then right.", required=True,
)  # fmt: skip
MAPPING = Section(
    "head.mapping",
    "With an MJCF `head.model`: the names of its joints, body H and cameras.",
    (
        CAMERAS,
        _part("head_body", "body", "The body whose frame is H at all joints zero (midway between the optical centres, x right, y down, z forward)."),
        _part("neck_yaw", "joint", "The neck's yaw joint: about W's +z at the base, or above a pitch at the base (the iCub's); leave out on a head without one (Model 2 only).", optional=True),
        _part("neck_pitch", "joint", "The neck's pitch joint, about W's +x (above the yaw, or at the base through W's origin), positive looking up."),
        Choice("eyes", EYE_KINDS, None, "How the eyes are driven: one motor on `left_eye` with `right_eye` following (coupled), a motor each (independent), or version and vergence actuators (version_vergence).", required=True),
        _part("left_eye", "joint", "The pan joint of the eye carrying Ca1 (at -x in H), positive inward."),
        _part("right_eye", "joint", "The pan joint of the eye carrying Ca2 (at +x in H), positive inward."),
        _part("neck_roll", "joint", "The neck's roll joint, held at zero (leave out on a head without one).", optional=True),
        _part("eye_tilt", "joint", "The eyes' common tilt joint, held at zero (leave out on a head without one).", optional=True),
        _part("version", "actuator", 'With `eyes = "version_vergence"`: the actuator of length (left - right) / 2.', optional=True),
        _part("vergence", "actuator", 'With `eyes = "version_vergence"`: the actuator of length left + right.', optional=True),
    ),
)  # fmt: skip


@dataclass(frozen=True)
class HeadMapping:
    """The names in a head's MJCF that headsim uses.

    ``neck_yaw``, ``neck_pitch``: the neck joints (yaw about W's z at the base, pitch
    about the yawed x, eq. (1)); ``neck_yaw`` may be None for a head with no neck yaw
    (Model 2 only).  ``eyes``: ``"coupled"`` (one motor on ``left_eye`` drives
    ``right_eye`` through an equality: the paper's head) or ``"independent"`` (a motor
    per eye).  ``left_eye``/``right_eye``: the pan joints of the eyes carrying
    ``cameras[0]`` (Ca1, at -x in H) and ``cameras[1]`` (Ca2); positive turns the eye
    inward.  ``head_body``: the body whose frame is H at all joints zero.
    ``eyes = "version_vergence"``: the pans are driven by two actuators, ``version``
    (``(left - right) / 2``) and ``vergence`` (``left + right``), e.g. on fixed tendons
    (the iCub's, (H7)); both eyes can be pointed on their own.  ``neck_roll`` and
    ``eye_tilt``: joints the method holds at zero, where the head has them.
    """

    head_body: str = names.HEAD
    neck_yaw: str | None = names.NECK_YAW
    neck_pitch: str = names.NECK_PITCH
    eyes: str = "coupled"
    left_eye: str = names.EYE_JOINTS[0]
    right_eye: str = names.EYE_JOINTS[1]
    cameras: tuple[str, str] = names.CAMERAS
    neck_roll: str | None = None
    eye_tilt: str | None = None
    version: str | None = None
    vergence: str | None = None

    def __post_init__(self) -> None:
        if self.eyes not in EYE_KINDS:
            raise HeadError("eyes", f"{self.eyes!r} is not a kind of eyes", ", ".join(EYE_KINDS))
        for key in ("version", "vergence"):
            given = getattr(self, key) is not None
            if given != (self.eyes == "version_vergence"):
                raise HeadError(
                    key,
                    "is given without eyes = 'version_vergence'"
                    if given
                    else "is not given, and eyes = 'version_vergence'",
                    "the version and vergence actuators with eyes = 'version_vergence', "
                    "else neither",
                )

    def prefixed(self, prefix: str) -> HeadMapping:
        """The same mapping with every name prefixed (a head attached to a scene)."""
        return HeadMapping(
            head_body=prefix + self.head_body,
            neck_yaw=None if self.neck_yaw is None else prefix + self.neck_yaw,
            neck_pitch=prefix + self.neck_pitch,
            eyes=self.eyes,
            left_eye=prefix + self.left_eye,
            right_eye=prefix + self.right_eye,
            cameras=(prefix + self.cameras[0], prefix + self.cameras[1]),
            neck_roll=_prefixed(prefix, self.neck_roll),
            eye_tilt=_prefixed(prefix, self.eye_tilt),
            version=_prefixed(prefix, self.version),
            vergence=_prefixed(prefix, self.vergence),
        )

    @property
    def joints(self) -> tuple[str, ...]:
        """Every joint the simulator moves: neck yaw (if any), pitch, left and right eye."""
        neck = (self.neck_yaw,) if self.neck_yaw is not None else ()
        return (*neck, self.neck_pitch, self.left_eye, self.right_eye)

    @property
    def independent(self) -> bool:
        """Whether each eye can be pointed on its own (its own motor, or version and
        vergence)."""
        return self.eyes != "coupled"

    @property
    def held(self) -> tuple[str, ...]:
        """The joints held at zero: neck roll and eye tilt, where given."""
        return tuple(j for j in (self.neck_roll, self.eye_tilt) if j is not None)


def _prefixed(prefix: str, name: str | None) -> str | None:
    return None if name is None else prefix + name


@dataclass(frozen=True)
class HeadModel:
    """A head: its name, its MJCF file (``None``: the scenes' own, the paper's head)
    and its mapping."""

    name: str = "paper"
    path: Path | None = None
    mapping: HeadMapping = HeadMapping()

    @property
    def is_paper(self) -> bool:
        """Whether this is the scenes' own head (models/head.xml), built in."""
        return self.path is None


#: The paper's head: models/head.xml, which every scene file includes.
PAPER = HeadModel()


def declared_head(path: Path, declared: dict[str, str]) -> HeadModel:
    """The head a file in models/ declares (:mod:`headsim.sim.head_files`): named by its
    stem, with the mapping its ``headsim:mapping.KEY`` entries give."""
    names: dict[str, Any] = {
        key.removeprefix("mapping."): value
        for key, value in declared.items()
        if key.startswith("mapping.")
    }
    if "cameras" in names:
        names["cameras"] = tuple(names["cameras"].split())
    try:
        return HeadModel(path.stem, path, HeadMapping(**names))
    except TypeError as err:  # a key HeadMapping does not have: a broken shipped file
        raise ValueError(f"{path.name}: <custom> {DECLARATION}mapping: {err}") from None


#: The shipped heads by name (:data:`headsim.sim.head_files.SHIPPED` gives each one's
#: line): the paper's, built into every scene, then every head file in models/ that
#: declares itself, alphabetically.
REGISTRY: dict[str, HeadModel] = {
    "paper": PAPER,
    **{name: declared_head(MODELS_DIR / f"{name}.xml", found) for name, found in DECLARED.items()},
}


def shipped(name: str) -> HeadModel:
    """A shipped head by name (:data:`REGISTRY`)."""
    if name not in REGISTRY:
        raise HeadError("model", f"unknown head {name!r}", f"{', '.join(SHIPPED)} or an MJCF file")
    return REGISTRY[name]


@dataclass(frozen=True)
class DesignedCamera:
    """An eye camera's intrinsics as its MJCF gives them: image size, px; focal lengths
    and principal point (OpenCV's convention), px."""

    width: int
    height: int
    fx_px: float
    fy_px: float
    cx_px: float
    cy_px: float


@dataclass(frozen=True)
class HeadGeometry:
    """A head's kinematics as its model was designed (all joints zero), m.

    ``baseline_m``: distance between the two optical centres; ``neck_d1_m``, ``neck_a2_m``:
    eq. (1)'s pitch-axis height above the base and H's height above the pitch axis, or
    for a neck that pitches at the base the yaw joint's height above the pitch axis and
    H's above that (H10); ``neck``: the joints' order and H's offset ahead of the yaw.
    """

    baseline_m: float
    neck_d1_m: float
    neck_a2_m: float
    neck: Neck = field(default_factory=Neck)
    cameras: tuple[DesignedCamera, ...] = ()


def _joint(model: mujoco.MjModel, key: str, name: str | None) -> int:
    if name is None:
        raise HeadError(key, "is not given", "a hinge joint of the model")
    try:
        joint = model.joint(name)
    except KeyError:
        raise HeadError(key, f"the model has no joint {name!r}", _list(model, "joint")) from None
    if int(model.jnt_type[joint.id]) != mujoco.mjtJoint.mjJNT_HINGE:
        raise HeadError(key, f"joint {name!r} is not a hinge", "a hinge (revolute) joint")
    return int(joint.id)


def _list(model: mujoco.MjModel, kind: str) -> str:
    count = {"joint": model.njnt, "camera": model.ncam, "body": model.nbody}[kind]
    found = [getattr(model, "cam" if kind == "camera" else kind)(i).name for i in range(count)]
    shown = ", ".join(repr(n) for n in found[:12] if n) + (", ..." if len(found) > 12 else "")
    return f"one of the model's {kind}s: {shown}" if shown else f"a named {kind}"


def _carries(model: mujoco.MjModel, ancestor: int, body: int) -> bool:
    while body > 0:
        if body == ancestor:
            return True
        body = int(model.body_parentid[body])
    return False


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.acos(min(1.0, abs(float(a @ b)) / float(np.linalg.norm(a) * np.linalg.norm(b))))


def check_head(
    model: mujoco.MjModel, mapping: HeadMapping, *, needs_yaw: bool = False
) -> HeadGeometry:
    """Hold ``mapping`` against the compiled ``model`` at its home pose; the head's
    designed geometry.  ``needs_yaw``: the procedure turns the neck to the midline
    (Model 1).  Raises :class:`HeadError` naming the mapping's key."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    try:
        head = model.body(mapping.head_body)
    except KeyError:
        raise HeadError(
            "head_body", f"the model has no body {mapping.head_body!r}", _list(model, "body")
        ) from None
    if mapping.neck_yaw is None and needs_yaw:
        raise HeadError(
            "neck_yaw",
            "is not given, and this procedure turns the neck to the midline (Model 1)",
            "the neck's yaw joint, or a procedure that keeps the neck still (Model 2)",
        )
    yaw = _joint(model, "neck_yaw", mapping.neck_yaw) if mapping.neck_yaw is not None else None
    pitch = _joint(model, "neck_pitch", mapping.neck_pitch)
    eyes = [_joint(model, key, getattr(mapping, key)) for key in ("left_eye", "right_eye")]
    for key in ("neck_roll", "eye_tilt"):
        if getattr(mapping, key) is not None:
            _joint(model, key, getattr(mapping, key))
    if mapping.eyes == "version_vergence":
        for key, coefs in (("version", (0.5, -0.5)), ("vergence", (1.0, 1.0))):
            _eye_actuator(model, data, key, getattr(mapping, key), eyes, coefs)
    cams = []
    for index, (key, name) in enumerate(
        zip(("cameras[0]", "cameras[1]"), mapping.cameras, strict=True)
    ):
        try:
            cam = model.camera(name)
        except KeyError:
            raise HeadError(
                key, f"the model has no camera {name!r}", _list(model, "camera")
            ) from None
        eye_body = int(model.jnt_bodyid[eyes[index]])
        if not _carries(model, eye_body, int(model.cam_bodyid[cam.id])):
            side = ("left_eye", "right_eye")[index]
            raise HeadError(
                key,
                f"camera {name!r} is not on the body of {side} joint {getattr(mapping, side)!r}",
                f"a camera on (or below) the body of the {side} joint",
            )
        width, height = (int(v) for v in model.cam_resolution[cam.id])
        if min(width, height) < MIN_CAMERA_SIDE_PX:
            # MuJoCo makes a camera without `resolution` 1 x 1 pixels.
            raise HeadError(
                key,
                f"camera {name!r} is {width} x {height} pixels (MuJoCo's size for a camera "
                "without resolution)",
                f'add resolution="WIDTH HEIGHT" to the camera, at least {MIN_CAMERA_SIDE_PX} '
                'pixels a side (resolution="640 480" takes the preset\'s cameras)',
            )
        cams.append(int(cam.id))

    world_from_head = np.eye(4)
    world_from_head[:3, :3] = data.xmat[head.id].reshape(3, 3)
    world_from_head[:3, 3] = data.xpos[head.id]
    for key, cam in zip(("cameras[0]", "cameras[1]"), cams, strict=True):
        # MuJoCo cameras look down their -z with y up: OpenCV's z is -z, y is -y.
        cam_mat = data.cam_xmat[cam].reshape(3, 3)
        looks = _angle(-cam_mat[:, 2], world_from_head[:3, 2])
        if looks > AXIS_TOLERANCE_RAD or float(cam_mat[:, 2] @ world_from_head[:3, 2]) > 0:
            raise HeadError(
                key,
                f"camera {model.cam(cam).name!r} looks {looks:.4g} rad off H's z at all joints zero",
                "a camera looking along H's z (forward) with its image x along H's x at home",
            )
    centres = [data.cam_xpos[c] for c in cams]
    baseline = centres[1] - centres[0]
    baseline_m = float(np.linalg.norm(baseline))
    if baseline_m <= 1e-4:
        raise HeadError(
            "cameras",
            f"the two cameras are {baseline_m:.2g} m apart",
            "cameras at least 0.1 mm apart",
        )
    axes = [data.xaxis[j] for j in eyes]
    between = _angle(axes[0], axes[1])
    if between > AXIS_TOLERANCE_RAD:
        raise HeadError(
            "right_eye",
            f"the eye pan axes are {between:.4g} rad from parallel",
            f"parallel axes, within {AXIS_TOLERANCE_RAD:g} rad",
        )
    for key, axis in zip(("left_eye", "right_eye"), axes, strict=True):
        off = abs(math.pi / 2 - _angle(axis, baseline))
        if off > AXIS_TOLERANCE_RAD:
            raise HeadError(
                key,
                f"its pan axis is {off:.4g} rad from perpendicular to the baseline",
                f"an axis perpendicular to the line between the cameras, within {AXIS_TOLERANCE_RAD:g} rad",
            )
    for key, axis, sign in zip(("left_eye", "right_eye"), axes, (1.0, -1.0), strict=True):
        if sign * float(world_from_head[:3, 1] @ axis) <= 0.0:
            raise HeadError(
                key,
                "a positive angle turns its eye outward",
                "a pan joint whose positive angle turns the eye inward (axis +y of H for the "
                "left eye, -y for the right)",
            )
    midpoint = (centres[0] + centres[1]) / 2
    if np.linalg.norm(midpoint - world_from_head[:3, 3]) > NECK_TOLERANCE_M:
        raise HeadError(
            "head_body",
            f"body {mapping.head_body!r} is {np.linalg.norm(midpoint - world_from_head[:3, 3]):.3g} m from the cameras' midpoint",
            "the body whose origin is midway between the two optical centres (frame H)",
        )
    x_h = baseline / baseline_m
    if abs(float(world_from_head[:3, 0] @ x_h) - 1.0) > AXIS_TOLERANCE_RAD:
        raise HeadError(
            "head_body",
            f"body {mapping.head_body!r}'s x axis is not along the baseline (Ca1 -> Ca2)",
            "frame H: x from the left camera to the right one, y down, z forward",
        )
    d1, a2, neck = _neck(model, data, mapping, yaw, pitch, world_from_head)
    return HeadGeometry(
        baseline_m=baseline_m,
        neck_d1_m=d1,
        neck_a2_m=a2,
        neck=neck,
        cameras=tuple(_designed_camera(model, cam) for cam in cams),
    )


def _designed_camera(model: mujoco.MjModel, cam: int) -> DesignedCamera:
    """A camera's intrinsics in pixels, from its resolution and its sensor size (or fovy)."""
    width, height = (int(v) for v in model.cam_resolution[cam])
    sensor = model.cam_sensorsize[cam]
    if float(sensor[0]) > 0.0 and float(sensor[1]) > 0.0:
        fx, fy, px, py = model.cam_intrinsic[cam]
        per_x, per_y = width / float(sensor[0]), height / float(sensor[1])
        fx_px, fy_px = float(fx) * per_x, float(fy) * per_y
        # MuJoCo's principal offset runs opposite to OpenCV's (see sim/model.py).
        cx, cy = (width - 1) / 2 - float(px) * per_x, (height - 1) / 2 - float(py) * per_y
    else:
        fx_px = fy_px = (height / 2) / math.tan(math.radians(float(model.cam_fovy[cam])) / 2)
        cx, cy = (width - 1) / 2, (height - 1) / 2
    return DesignedCamera(width, height, fx_px, fy_px, cx, cy)


def _eye_actuator(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    key: str,
    name: str | None,
    eyes: list[int],
    coefs: tuple[float, float],
) -> int:
    """The version or vergence actuator: its length must be ``coefs`` . (left, right)."""
    try:
        actuator = int(model.actuator(name).id)
    except KeyError:
        found = ", ".join(repr(model.actuator(i).name) for i in range(min(model.nu, 12)))
        raise HeadError(
            key, f"the model has no actuator {name!r}", f"one of the model's actuators: {found}"
        ) from None
    per_joint = actuator_coefficients(model, actuator)
    moment = np.array([per_joint.pop(j, 0.0) for j in eyes])
    others = np.array(list(per_joint.values()))
    if not np.allclose(moment, coefs, atol=1e-9) or np.abs(others).max(initial=0.0) > 0:
        raise HeadError(
            key,
            f"actuator {name!r} moves the pans by {np.round(moment, 6).tolist()} "
            "(left, right) per unit",
            f"an actuator whose length is {coefs[0]:g} left {coefs[1]:+g} right and nothing else "
            "((H7): version (l - r) / 2, vergence l + r)",
        )
    return actuator


def actuator_coefficients(model: mujoco.MjModel, actuator: int) -> dict[int, float]:
    """An actuator's length per unit of each joint it moves (joint id: coefficient), for a
    joint or a fixed-tendon transmission; empty for any other."""
    gear = float(model.actuator_gear[actuator, 0])
    target = int(model.actuator_trnid[actuator, 0])
    kind = int(model.actuator_trntype[actuator])
    if kind == mujoco.mjtTrn.mjTRN_JOINT:
        return {target: gear}
    if kind != mujoco.mjtTrn.mjTRN_TENDON:
        return {}
    start, count = int(model.tendon_adr[target]), int(model.tendon_num[target])
    coefs: dict[int, float] = {}
    for w in range(start, start + count):
        if int(model.wrap_type[w]) != mujoco.mjtWrap.mjWRAP_JOINT:
            return {}
        joint = int(model.wrap_objid[w])
        coefs[joint] = coefs.get(joint, 0.0) + gear * float(model.wrap_prm[w])
    return coefs


def eye_motor_range(model: mujoco.MjModel, mapping: HeadMapping) -> tuple[float, float]:
    """The range of the eye motor as the counter-yaw (both eyes inward by one angle), rad:
    the left pan's, within half the vergence actuator's range where eyes are so driven."""
    low, high = (float(v) for v in model.joint(mapping.left_eye).range)
    if mapping.vergence is not None:
        actuator = int(model.actuator(mapping.vergence).id)
        if bool(model.actuator_ctrllimited[actuator]):
            v_low, v_high = (float(v) / 2 for v in model.actuator_ctrlrange[actuator])
            low, high = max(low, v_low), min(high, v_high)
    return low, high


def actuator_on(model: mujoco.MjModel, joint: str) -> int:
    """The id of the actuator driving ``joint`` directly, or -1 (kinematic settling only)."""
    joint_id = int(model.joint(joint).id)
    for actuator in range(model.nu):
        if (
            int(model.actuator_trntype[actuator]) == mujoco.mjtTrn.mjTRN_JOINT
            and int(model.actuator_trnid[actuator, 0]) == joint_id
        ):
            return actuator
    return -1


def _check_axis(
    data: mujoco.MjData,
    joint: int,
    along: int,
    across: tuple[int, int],
    key: str,
    problem: str,
    allowed: str,
) -> np.ndarray:
    """A neck joint's anchor in W, after checking that its axis is W's axis ``along`` and
    passes through W's ``across`` coordinates zero; else :class:`HeadError` on ``key``."""
    axis, anchor = data.xaxis[joint], data.xanchor[joint]
    off = float(np.hypot(anchor[across[0]], anchor[across[1]]))
    if float(axis[along]) < 1.0 - AXIS_TOLERANCE_RAD or off > NECK_TOLERANCE_M:
        raise HeadError(key, problem, allowed)
    return np.asarray(anchor)


def _neck(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    mapping: HeadMapping,
    yaw: int | None,
    pitch: int,
    world_from_head: np.ndarray,
) -> tuple[float, float, Neck]:
    """d1, a2 and the layout of the model's neck (H10), after checking that it is one."""
    expected = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]).T  # H's axes in W at zero
    if not np.allclose(world_from_head[:3, :3], expected, atol=AXIS_TOLERANCE_RAD):
        raise HeadError(
            "head_body",
            "at all joints zero frame H does not look along W's +y with its y down",
            "a head that looks forward (+y) at home, H's x to the right, y down",
        )
    pitch_first = yaw is not None and _carries(
        model, int(model.jnt_bodyid[pitch]), int(model.jnt_bodyid[yaw])
    )
    head = world_from_head[:3, 3]
    if pitch_first:
        assert yaw is not None
        _check_axis(
            data,
            pitch,
            0,
            (1, 2),
            "neck_pitch",
            f"joint {mapping.neck_pitch!r} is not W's +x axis through the world origin",
            "a neck pitch at the base about W's +x through W's origin, positive looking up "
            "(H10), or a yaw at the base (eq. (1))",
        )
        anchor = _check_axis(
            data,
            yaw,
            2,
            (0, 1),
            "neck_yaw",
            f"joint {mapping.neck_yaw!r} is not along W's +z through the pitch axis",
            "the neck's yaw about the pitched +z, meeting the pitch axis, positive turning "
            "left (H10)",
        )
        if abs(head[0]) > NECK_TOLERANCE_M:
            raise HeadError(
                "head_body",
                f"H's origin is {abs(head[0]):.3g} m to the side of the neck's axes",
                "H in the plane of the yaw axis and W's y (H10)",
            )
        d1 = float(anchor[2])
        return d1, float(head[2]) - d1, Neck("pitch_yaw", float(head[1]))
    if yaw is not None:
        _check_axis(
            data,
            yaw,
            2,
            (0, 1),
            "neck_yaw",
            f"joint {mapping.neck_yaw!r} is not W's +z axis through the world origin",
            "the neck's yaw about W's +z at the base, positive turning left (eq. (1))",
        )
    anchor = _check_axis(
        data,
        pitch,
        0,
        (0, 1),
        "neck_pitch",
        f"joint {mapping.neck_pitch!r} is not along W's +x above the base",
        "the neck's pitch about the yawed +x axis above the yaw axis, positive looking up (eq. (1))",
    )
    if np.hypot(head[0], head[1]) > NECK_TOLERANCE_M:
        raise HeadError(
            "head_body",
            f"H's origin is {np.hypot(head[0], head[1]):.3g} m off the neck's axis",
            "H above the pitch axis, on the yaw axis (eq. (1))",
        )
    d1 = float(anchor[2])
    return d1, float(head[2]) - d1, Neck()


__all__ = [
    "AXIS_TOLERANCE_RAD",
    "EYE_KINDS",
    "MODELS_DIR",
    "PAPER",
    "REGISTRY",
    "SHIPPED",
    "DesignedCamera",
    "HeadError",
    "HeadGeometry",
    "HeadMapping",
    "HeadModel",
    "actuator_coefficients",
    "actuator_on",
    "check_head",
    "declared_head",
    "eye_motor_range",
    "shipped",
]
