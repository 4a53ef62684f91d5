"""What the tests of the shipped head files share: loading a head by name, posing it,
its frames in W (docs/equations.md, "Frames and signs")."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from headsim.sim.head_files import MODELS_DIR
from headsim.sim.heads import REGISTRY, HeadMapping

#: H's axes in W at all joints 0, as columns: x right, y down, z forward.
W_FROM_H_HOME = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
#: A MuJoCo camera frame (x right, y up, looking down -z) to the OpenCV one (y down, z ahead).
MUJOCO_FROM_OPENCV = np.diag([1.0, -1.0, -1.0])
TIGHT = 1e-12
#: Element kinds that must all carry a unique name (the world body excepted).
NAMED_KINDS = {
    mujoco.mjtObj.mjOBJ_BODY: "nbody",
    mujoco.mjtObj.mjOBJ_JOINT: "njnt",
    mujoco.mjtObj.mjOBJ_GEOM: "ngeom",
    mujoco.mjtObj.mjOBJ_SITE: "nsite",
    mujoco.mjtObj.mjOBJ_CAMERA: "ncam",
    mujoco.mjtObj.mjOBJ_ACTUATOR: "nu",
    mujoco.mjtObj.mjOBJ_TENDON: "ntendon",
    mujoco.mjtObj.mjOBJ_EQUALITY: "neq",
    mujoco.mjtObj.mjOBJ_KEY: "nkey",
}


def head_file(name: str) -> Path:
    """A shipped head's MJCF file (the paper's: models/head.xml, which the scenes include)."""
    return REGISTRY[name].path or MODELS_DIR / "head.xml"


def load(name: str) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(head_file(name)))


def names(name: str) -> HeadMapping:
    return REGISTRY[name].mapping


def posed(model: mujoco.MjModel, **angles_rad: float) -> mujoco.MjData:
    """Data at the home keyframe with the named joints set, kinematics computed."""
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    for joint, angle in angles_rad.items():
        data.qpos[model.joint(joint).qposadr[0]] = angle
    mujoco.mj_forward(model, data)
    return data


def w_from_h(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    return data.xmat[model.body(names(name).head_body).id].reshape(3, 3).copy()


def w_from_opencv_camera(data: mujoco.MjData, model: mujoco.MjModel, camera: str) -> np.ndarray:
    return data.cam_xmat[model.camera(camera).id].reshape(3, 3) @ MUJOCO_FROM_OPENCV


def joint_axis_w(model: mujoco.MjModel, data: mujoco.MjData, joint: str) -> np.ndarray:
    return data.xaxis[model.joint(joint).id].copy()


def rot_z(angle_rad: float) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def settle(model: mujoco.MjModel, ctrl: dict[str, float], seconds: float = 2.0) -> mujoco.MjData:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    for motor, target in ctrl.items():
        data.ctrl[model.actuator(motor).id] = target
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return data
