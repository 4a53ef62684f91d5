"""Building scenes: load an MJCF scene and apply head settings through MjSpec.

The XML files in ``models/`` (installed as ``headsim.models``) hold the defaults (ideal cameras, D = 150 mm);
:func:`build_model` edits a fresh spec from them with a :class:`HeadSettings`
and compiles it.  Props (markers, chessboards) can be added the same way.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace
from pathlib import Path

import mujoco
import numpy as np

from headsim.geometry.heads import Neck
from headsim.geometry.kinematics import eye_from_camera_rotation
from headsim.sim import names
from headsim.sim.heads import (
    MODELS_DIR,
    PAPER,
    DesignedCamera,
    HeadError,
    HeadGeometry,
    HeadMapping,
    HeadModel,
    check_head,
)
from headsim.sim.imperfections.distortion import DistortionCanvas, distortion_canvas
from headsim.sim.settings import MAX_IMAGE_SIDE, CameraSettings, HeadSettings, SettingsError
from headsim.sim.textured_scene import RoomSpec, add_room

#: Sensor pixel pitch used to express pixel intrinsics in MuJoCo's length units, m.
PIXEL_PITCH_M = 1e-5


def scene_path(scene: str | Path) -> Path:
    """Resolve a scene short name (``names.SCENES``) or a path to an MJCF file."""
    if isinstance(scene, str) and scene in names.SCENES:
        return MODELS_DIR / names.SCENES[scene]
    path = Path(scene)
    if path.suffix == ".xml" and path.is_file():
        return path
    raise SettingsError(
        f"unknown scene {str(scene)!r}; allowed: {', '.join(sorted(names.SCENES))} or a path to an MJCF .xml file"
    )


#: MuJoCo camera axes (x right, y up, looking down -z) in OpenCV camera axes, and back.
CV_FROM_MJCAM = np.diag([1.0, -1.0, -1.0])


def _quat_from_matrix(matrix: np.ndarray) -> np.ndarray:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(matrix).reshape(9))
    return quat


@dataclass(frozen=True)
class BuiltModel:
    """A compiled scene and, per camera, how it is rendered; ``names``: the head's
    mapping with the names as compiled into the scene."""

    model: mujoco.MjModel
    spec: mujoco.MjSpec
    canvases: tuple[DistortionCanvas, DistortionCanvas]
    names: HeadMapping = PAPER.mapping


#: What a head attached to a scene has its names prefixed with.
HEAD_PREFIX = "head:"


def load_spec(scene: str | Path = "default", head: HeadModel = PAPER) -> mujoco.MjSpec:
    """A fresh, editable spec of a scene, with ``head`` in place of the scenes' own."""
    spec = mujoco.MjSpec.from_file(str(scene_path(scene)))
    if head.is_paper:
        return spec
    spec.delete(spec.body(names.NECK_BASE))  # its joints, actuators and equality go with it
    for key in list(spec.keys):
        spec.delete(key)
    head_spec = mujoco.MjSpec.from_file(str(head.path))
    for key in list(head_spec.keys):  # home is all joints zero, the scene's qpos0
        head_spec.delete(key)
    head_spec.nkey = spec.nkey  # a <size nkey> the file may carry
    spec.attach(head_spec, frame=spec.worldbody.add_frame(), prefix=HEAD_PREFIX)
    return spec


def head_names(head: HeadModel) -> HeadMapping:
    """``head``'s mapping with its names as they are in a scene built by :func:`load_spec`."""
    return head.mapping if head.is_paper else head.mapping.prefixed(HEAD_PREFIX)


@dataclass(frozen=True)
class _Frames:
    """Where the settings' lengths and mounts act in a head's spec (all joints zero)."""

    #: The body that d1 moves: the pitch joint's (eq. (1)) or the yaw joint's (H10).
    d1_body: str
    head_body: str
    eye_bodies: tuple[str, str]
    #: W's z in the d1 body's parent and in H's parent; H's x in each eye body's parent.
    up_in_d1_parent: np.ndarray
    up_in_head_parent: np.ndarray
    x_in_eye_parents: tuple[np.ndarray, np.ndarray]
    #: Each eye body's frame from H (rotation) and its designed camera position, m.
    eye_from_head: tuple[np.ndarray, np.ndarray]
    designed: HeadGeometry


def _frames(spec: mujoco.MjSpec, mapping: HeadMapping) -> _Frames:
    """The designed head of ``spec``, checked against ``mapping``."""
    model = spec.compile()
    designed = check_head(model, mapping)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)

    def rot(body: int) -> np.ndarray:
        return data.xmat[body].reshape(3, 3)

    d1_joint = mapping.neck_yaw if designed.neck.order == "pitch_yaw" else mapping.neck_pitch
    d1_body = int(model.jnt_bodyid[model.joint(d1_joint).id])
    head_body = int(model.body(mapping.head_body).id)
    eyes = [int(model.jnt_bodyid[model.joint(j).id]) for j in (mapping.left_eye, mapping.right_eye)]
    x_w = rot(head_body)[:, 0]
    up = np.array([0.0, 0.0, 1.0])
    parent = model.body_parentid
    return _Frames(
        d1_body=model.body(d1_body).name,
        head_body=mapping.head_body,
        eye_bodies=(model.body(eyes[0]).name, model.body(eyes[1]).name),
        up_in_d1_parent=rot(parent[d1_body]).T @ up,
        up_in_head_parent=rot(parent[head_body]).T @ up,
        x_in_eye_parents=(rot(parent[eyes[0]]).T @ x_w, rot(parent[eyes[1]]).T @ x_w),
        eye_from_head=(rot(eyes[0]).T @ rot(head_body), rot(eyes[1]).T @ rot(head_body)),
        designed=designed,
    )


def _apply_lengths(spec: mujoco.MjSpec, settings: HeadSettings, frames: _Frames) -> None:
    """Move a head's links by the settings' lengths minus the designed ones."""
    d = frames.designed
    lower = spec.body(frames.d1_body)
    lower.pos = np.asarray(lower.pos) + (settings.neck_d1_m - d.neck_d1_m) * frames.up_in_d1_parent
    head = spec.body(frames.head_body)
    head.pos = np.asarray(head.pos) + (settings.neck_a2_m - d.neck_a2_m) * frames.up_in_head_parent
    half = (settings.baseline_m - d.baseline_m) / 2
    for sign, name, x_parent in zip(
        (-1.0, 1.0), frames.eye_bodies, frames.x_in_eye_parents, strict=True
    ):
        body = spec.body(name)
        body.pos = np.asarray(body.pos) + sign * half * x_parent


def apply_settings(
    spec: mujoco.MjSpec, settings: HeadSettings
) -> tuple[DistortionCanvas, DistortionCanvas]:
    """Write baseline, neck D-H offsets, cameras (with optical-centre offsets and yaw-axis
    tilts) into ``spec``; return the render canvases.  The paper's head takes the lengths
    as they are; another head is moved by them less its design (:mod:`headsim.sim.heads`)."""
    head = settings.head
    mapping = head_names(head)
    if head.is_paper:
        spec.body(names.NECK_PITCH_LINK).pos = [0.0, 0.0, settings.neck_d1_m]
        spec.body(names.HEAD).pos = [0.0, 0.0, settings.neck_a2_m]
        half = settings.baseline_m / 2
        spec.body(names.EYE_BODIES[0]).pos = [-half, 0.0, 0.0]
        spec.body(names.EYE_BODIES[1]).pos = [half, 0.0, 0.0]
        eye_from_head: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
        designed_pos: list[np.ndarray | None] = [None, None]
    else:
        frames = _frames(spec, mapping)
        _apply_lengths(spec, settings, frames)
        eye_from_head = frames.eye_from_head
        # A copy: np.asarray would view the spec's own array, which the loop below rewrites.
        designed_pos = [np.array(spec.camera(c).pos, dtype=float) for c in mapping.cameras]

    canvases = []
    k = settings.render.supersample
    spec.visual.quality.offsamples = settings.render.offsamples
    eye_joints = (mapping.left_eye, mapping.right_eye)
    for index, (cam_name, cam) in enumerate(zip(mapping.cameras, settings.cameras, strict=True)):
        canvas = distortion_canvas(cam, MAX_IMAGE_SIDE // k)
        width_c, height_c = canvas.size
        pcx, pcy = canvas.principal
        mj_cam = spec.camera(cam_name)
        # Supersampled k times: pixel i of the canvas is the area average of
        # pixels k i .. k i + k - 1, whose centres average to k i + (k - 1) / 2.
        mj_cam.resolution = [k * width_c, k * height_c]
        mj_cam.sensor_size = [k * width_c * PIXEL_PITCH_M, k * height_c * PIXEL_PITCH_M]
        mj_cam.focal_pixel = [k * cam.kx, k * cam.ky]
        # MuJoCo's principal offset is from the image centre with the opposite
        # sign of OpenCV's habit: cx = (W - 1) / 2 - principalpixel_x (checked by
        # rendering, tests/sim/test_render.py); supersampled, every term scales by k.
        mj_cam.principal_pixel = [k * ((width_c - 1) / 2 - pcx), k * ((height_c - 1) / 2 - pcy)]
        eye_from_cv = eye_from_camera_rotation(
            names.EYE_CAMERAS[index].inward,
            cam.mount_yaw_rad,
            cam.mount_pitch_rad,
            cam.mount_roll_rad,
        )
        body_from_head = eye_from_head[index]
        if body_from_head is not None:
            eye_from_cv = body_from_head @ eye_from_cv
        mj_cam.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT  # drop the XML's xyaxes
        mj_cam.quat = _quat_from_matrix(eye_from_cv @ CV_FROM_MJCAM)
        # Optical centre off the yaw axis: forward along the optical axis, sideways along x.
        offset_cv = np.array([cam.side_offset_m, 0.0, cam.nodal_offset_m])
        mj_cam.pos = eye_from_cv @ offset_cv
        # Yaw axis leaning forward about H's x (eye2's axis is -y, mirrored).
        tilt = cam.eye_axis_tilt_rad
        axis_sign = names.EYE_CAMERAS[index].inward
        axis_head = [0.0, axis_sign * np.cos(tilt), axis_sign * np.sin(tilt)]
        if body_from_head is not None:
            mj_cam.pos = designed_pos[index] + mj_cam.pos
            axis_head = list(body_from_head @ np.array(axis_head))
        spec.joint(eye_joints[index]).axis = axis_head
        canvases.append(canvas)

    spec.visual.global_.offwidth = k * max(c.size[0] for c in canvases)
    spec.visual.global_.offheight = k * max(c.size[1] for c in canvases)
    return canvases[0], canvases[1]


def build_model(
    scene: str | Path = "default",
    settings: HeadSettings | None = None,
    room: RoomSpec | None = None,
) -> BuiltModel:
    """Load ``scene``, put ``room`` in it (:mod:`headsim.sim.textured_scene`; None: the
    scene as it is), apply ``settings`` (default: ideal head) and compile."""
    settings = settings or HeadSettings()
    spec = load_spec(scene, settings.head)
    if room is not None:
        add_room(spec, room)
    canvases = apply_settings(spec, settings)
    return BuiltModel(
        model=spec.compile(), spec=spec, canvases=canvases, names=head_names(settings.head)
    )


def add_marker(
    spec: mujoco.MjSpec,
    name: str,
    position_world_m: np.ndarray,
    radius_m: float = 0.004,
    rgba: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 1.0),
) -> None:
    """Add an emissive spherical marker on a mocap body named ``name``."""
    if radius_m <= 0:
        raise SettingsError(f"marker radius_m must be > 0, got {radius_m}")
    body = spec.worldbody.add_body(name=name, mocap=True, pos=list(map(float, position_world_m)))
    material = spec.add_material(name=f"{name}_material", rgba=list(rgba), emission=1.0)
    material.specular = 0.0
    material.shininess = 0.0
    body.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[radius_m, 0, 0],
        material=material.name,
        contype=0,
        conaffinity=0,
    )


@functools.cache
def design(head: HeadModel) -> HeadGeometry:
    """``head``'s designed geometry in the base scene, its mapping checked
    (:func:`check_head`).  Raises :class:`HeadError`, or MuJoCo's ValueError for a file
    that does not compile."""
    try:
        return check_head(load_spec("base", head).compile(), head_names(head))
    except HeadError as err:  # say the names as the user's file and mapping spell them
        quoted = repr(HEAD_PREFIX)[:-1]  # 'head:

        def unprefixed(text: str) -> str:
            return text if head.is_paper else text.replace(quoted, quoted[0])

        raise HeadError(err.key, unprefixed(err.problem), unprefixed(err.allowed)) from None


def on_head(settings: HeadSettings, head: HeadModel) -> HeadSettings:
    """``settings`` (of the paper's head, e.g. a preset) moved onto ``head``: each length
    is its design plus the settings' departure from the paper's design, in truth and in
    belief; the paper's head takes them as they are."""
    if head.is_paper:
        return replace(settings, head=head)
    designed, nominal = design(head), HeadSettings()

    def moved(value: float, name: str) -> float:
        return value - float(getattr(nominal, name)) + float(getattr(designed, name))

    cameras = tuple(
        _own_camera(cam, own) for cam, own in zip(settings.cameras, designed.cameras, strict=True)
    )
    belief = settings.belief
    if belief is not None:
        belief = replace(
            belief,
            baseline_m=moved(belief.baseline_m, "baseline_m"),
            neck_d1_m=moved(belief.neck_d1_m, "neck_d1_m"),
            neck_a2_m=moved(belief.neck_a2_m, "neck_a2_m"),
        )
    return replace(
        settings,
        head=head,
        belief=belief,
        cameras=(cameras[0], cameras[1]),
        baseline_m=moved(settings.baseline_m, "baseline_m"),
        neck_d1_m=moved(settings.neck_d1_m, "neck_d1_m"),
        neck_a2_m=moved(settings.neck_a2_m, "neck_a2_m"),
    )


def _nominal(own: DesignedCamera) -> bool:
    """Whether a head's camera is the nominal one (640 x 480, 45 degree fovy, centred)."""
    nominal = CameraSettings()
    return (own.width, own.height) == (nominal.width, nominal.height) and all(
        math.isclose(a, b, rel_tol=1e-5)
        for a, b in zip(
            (own.fx_px, own.fy_px, own.cx_px, own.cy_px),
            (nominal.kx, nominal.ky, *nominal.principal),
            strict=True,
        )
    )


def has_own_cameras(head: HeadModel) -> bool:
    """Whether ``head``'s MJCF cameras are not the nominal ones: the presets then take
    the head's image size, focal lengths and principal points, and not the paper's
    cameras' initial directions."""
    return not head.is_paper and not all(_nominal(c) for c in design(head).cameras)


def _own_camera(cam: CameraSettings, own: DesignedCamera) -> CameraSettings:
    """``cam`` (a preset's) on a head whose MJCF camera is ``own``: the head's image size,
    focal lengths and principal point, the preset's lens distortion, mount, offsets and
    noise.  A head with the nominal camera (640 x 480, 45 degree fovy) keeps ``cam``."""
    if _nominal(own):
        return cam
    return replace(
        cam,
        width=own.width,
        height=own.height,
        kx=own.fx_px,
        ky=own.fy_px,
        cx=own.cx_px,
        cy=own.cy_px,
    )


def neck_of(head: HeadModel) -> Neck:
    """The layout of ``head``'s neck (H10): eq. (1)'s for the paper's head; with the
    lengths of a :class:`HeadSettings` or its belief it maps H to W."""
    return Neck() if head.is_paper else design(head).neck
