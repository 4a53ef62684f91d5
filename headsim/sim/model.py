"""Building scenes: load an MJCF scene and apply head settings through MjSpec.

The XML files in ``models/`` (installed as ``headsim.models``) hold the defaults (ideal cameras, D = 150 mm);
:func:`build_model` edits a fresh spec from them with a :class:`HeadSettings`
and compiles it.  Props (markers, chessboards) can be added the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import mujoco
import numpy as np

from headsim.geometry.kinematics import eye_from_camera_rotation
from headsim.sim import names
from headsim.sim.optics import DistortionCanvas, distortion_canvas
from headsim.sim.settings import MAX_IMAGE_SIDE, HeadSettings, SettingsError

#: The head and scene MJCF files: the repository's models/, installed as package data.
MODELS_DIR = Path(str(resources.files("headsim.models")))
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
    """A compiled scene and, per camera, how it is rendered."""

    model: mujoco.MjModel
    spec: mujoco.MjSpec
    canvases: tuple[DistortionCanvas, DistortionCanvas]


def load_spec(scene: str | Path = "default") -> mujoco.MjSpec:
    """A fresh, editable spec of a scene."""
    return mujoco.MjSpec.from_file(str(scene_path(scene)))


def apply_settings(
    spec: mujoco.MjSpec, settings: HeadSettings
) -> tuple[DistortionCanvas, DistortionCanvas]:
    """Write baseline, neck D-H offsets, cameras (with optical-centre offsets and yaw-axis
    tilts) into ``spec``; return the render canvases."""
    spec.body(names.NECK_PITCH_LINK).pos = [0.0, 0.0, settings.neck_d1_m]
    spec.body(names.HEAD).pos = [0.0, 0.0, settings.neck_a2_m]
    half = settings.baseline_m / 2
    spec.body(names.EYE_BODIES[0]).pos = [-half, 0.0, 0.0]
    spec.body(names.EYE_BODIES[1]).pos = [half, 0.0, 0.0]

    canvases = []
    k = settings.render.supersample
    spec.visual.quality.offsamples = settings.render.offsamples
    for index, (cam_name, cam) in enumerate(zip(names.CAMERAS, settings.cameras, strict=True)):
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
        mj_cam.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT  # drop the XML's xyaxes
        mj_cam.quat = _quat_from_matrix(eye_from_cv @ CV_FROM_MJCAM)
        # Optical centre off the yaw axis: forward along the optical axis, sideways along x.
        offset_cv = np.array([cam.side_offset_m, 0.0, cam.nodal_offset_m])
        mj_cam.pos = eye_from_cv @ offset_cv
        # Yaw axis leaning forward about H's x (eye2's axis is -y, mirrored).
        tilt = cam.eye_axis_tilt_rad
        axis_sign = names.EYE_CAMERAS[index].inward
        spec.joint(names.EYE_JOINTS[index]).axis = [
            0.0,
            axis_sign * np.cos(tilt),
            axis_sign * np.sin(tilt),
        ]
        canvases.append(canvas)

    spec.visual.global_.offwidth = k * max(c.size[0] for c in canvases)
    spec.visual.global_.offheight = k * max(c.size[1] for c in canvases)
    return canvases[0], canvases[1]


def build_model(scene: str | Path = "default", settings: HeadSettings | None = None) -> BuiltModel:
    """Load ``scene``, apply ``settings`` (default: ideal head) and compile."""
    settings = settings or HeadSettings()
    spec = load_spec(scene)
    canvases = apply_settings(spec, settings)
    return BuiltModel(model=spec.compile(), spec=spec, canvases=canvases)


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
