"""A head headsim has never seen, built from scratch with ``mujoco.MjSpec``: other names
for every body, joint, camera and actuator, other lengths and cameras, a motor per eye.

Frames as docs/equations.md, "Frames and signs": W at the neck base (x right, y forward,
z up); the head body ``face`` is H (x right, y down, z forward: xyaxes "1 0 0 0 0 -1");
each eye's pan axis is H's +y (left) or -y (right), so positive turns it inward; each
camera is OpenCV-aligned with H at home (MuJoCo cameras look down -z, y up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco

from headsim.sim.heads import HeadMapping


@dataclass(frozen=True)
class BuiltHead:
    """A head written as MJCF: its file, its mapping and its designed lengths, m;
    ``focal_px`` and ``resolution`` (width, height) of both cameras."""

    path: Path
    mapping: HeadMapping
    baseline_m: float
    d1_m: float
    a2_m: float
    focal_px: float
    resolution: tuple[int, int]
    #: The [head.mapping] table of a scenario, as TOML lines.
    toml: str = field(repr=False, default="")


def _mapping_toml(mapping: HeadMapping) -> str:
    lines = [
        f'head_body = "{mapping.head_body}"',
        f'neck_pitch = "{mapping.neck_pitch}"',
        f'eyes = "{mapping.eyes}"',
        f'left_eye = "{mapping.left_eye}"',
        f'right_eye = "{mapping.right_eye}"',
        f'cameras = ["{mapping.cameras[0]}", "{mapping.cameras[1]}"]',
    ]
    if mapping.neck_yaw is not None:
        lines.insert(1, f'neck_yaw = "{mapping.neck_yaw}"')
    return "\n".join(lines) + "\n"


def build_head(
    path: Path,
    *,
    baseline_m: float = 0.10,
    d1_m: float = 0.15,
    a2_m: float = 0.07,
    width: int = 480,
    height: int = 360,
    focal_px: float = 420.0,
    right_axis_tilt_rad: float = 0.0,
    axes_turn_rad: float = 0.0,
    head_camera: bool = False,
) -> BuiltHead:
    """Write the head to ``path``; its mapping.

    ``right_axis_tilt_rad``: the right pan axis tilted about H's x (no longer parallel to
    the left one, still perpendicular to the baseline).  ``axes_turn_rad``: both pan
    axes turned about H's z (still parallel, no longer perpendicular to the baseline).
    ``head_camera``: a third camera, ``brow_imager``, on the head body, on no eye.
    """
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    hidden = {"group": 3, "contype": 0, "conaffinity": 0}
    base = spec.worldbody.add_body(name="torso_top")
    yaw_link = base.add_body(name="atlas")
    yaw_link.add_joint(
        name="pan", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], range=[-1.5, 1.5]
    )
    yaw_link.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.02, 0, 0], **hidden)
    tilt_link = yaw_link.add_body(name="skull_base", pos=[0, 0, d1_m])
    tilt_link.add_joint(
        name="nod", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[1, 0, 0], range=[-0.7, 0.7]
    )
    tilt_link.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.02, 0, 0], **hidden)
    face = tilt_link.add_body(name="face", pos=[0, 0, a2_m], xyaxes=[1, 0, 0, 0, 0, -1])
    face.add_geom(
        type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.05, 0.03, 0.02], pos=[0, 0, -0.05], **hidden
    )
    camera = {
        "xyaxes": [1, 0, 0, 0, -1, 0],
        "resolution": [width, height],
        "sensor_size": [width * 1e-5, height * 1e-5],
        "focal_pixel": [focal_px, focal_px],
        "principal_pixel": [0, 0],
    }
    c, s = math.cos(axes_turn_rad), math.sin(axes_turn_rad)
    ct, st = math.cos(right_axis_tilt_rad), math.sin(right_axis_tilt_rad)
    # In H (the eye bodies are aligned with it): left +y, right -y, each turned about z.
    axes = {"port": [-s, c, 0.0], "starboard": [s * ct, -c * ct, st]}
    for side, x in (("port", -baseline_m / 2), ("starboard", baseline_m / 2)):
        eye = face.add_body(name=f"{side}_eyeball", pos=[x, 0, 0])
        eye.add_joint(
            name=f"{side}_pan", type=mujoco.mjtJoint.mjJNT_HINGE, axis=axes[side], range=[-0.6, 0.6]
        )
        eye.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01, 0, 0], **hidden)
        eye.add_camera(name=f"{side}_imager", **camera)
        spec.add_actuator(
            name=f"{side}_pan_servo", target=f"{side}_pan", trntype=mujoco.mjtTrn.mjTRN_JOINT
        ).set_to_position(kp=4)
    if head_camera:
        face.add_camera(name="brow_imager", pos=[-baseline_m / 2, -0.03, 0], **camera)
    for joint in ("pan", "nod"):
        spec.add_actuator(
            name=f"{joint}_servo", target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT
        ).set_to_position(kp=40)
    spec.add_key(name="home")
    spec.compile()
    path.write_text(spec.to_xml())
    mapping = HeadMapping(
        head_body="face",
        neck_yaw="pan",
        neck_pitch="nod",
        eyes="independent",
        left_eye="port_pan",
        right_eye="starboard_pan",
        cameras=("port_imager", "starboard_imager"),
    )
    return BuiltHead(
        path, mapping, baseline_m, d1_m, a2_m, focal_px, (width, height), _mapping_toml(mapping)
    )
