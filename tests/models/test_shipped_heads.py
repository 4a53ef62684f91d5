"""The shipped head models other than head.xml, with real MuJoCo: frames, axes, signs, cameras.

Every head keeps the project's frames (docs/equations.md, "Frames and signs"): W at the
neck base (x right, y forward, z up), the head body at H (origin midway between the
optical centres, x right, y down, z forward) at all joints 0, each camera OpenCV-aligned
with H there and on its eye's pan axis, and each pan angle positive inward.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import pytest

from headsim.sim.model import MODELS_DIR

#: H's axes in W at all joints 0, as columns: x right, y down, z forward.
W_FROM_H_HOME = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
#: A MuJoCo camera frame (x right, y up, looking down -z) to the OpenCV one (y down, z ahead).
MUJOCO_FROM_OPENCV = np.diag([1.0, -1.0, -1.0])
TIGHT = 1e-12


@dataclass(frozen=True)
class ShippedHead:
    """What a test needs to know of one head file: its names and its cited numbers."""

    file: str
    head_body: str
    cameras: tuple[str, str]  # left (x = -D/2 in H), right
    pans: tuple[str, str]  # left, right; positive = inward
    neck_yaw: str
    neck_pitch: str
    baseline_m: float
    resolution: tuple[int, int]  # width, height in pixels
    focal_px: float


INDEPENDENT_EYES = ShippedHead(
    file="independent_eyes.xml",
    head_body="head_frame",
    cameras=("left_camera", "right_camera"),
    pans=("left_eye_pan", "right_eye_pan"),
    neck_yaw="neck_yaw_joint",
    neck_pitch="neck_pitch_joint",
    baseline_m=0.150,
    resolution=(640, 480),
    focal_px=579.4112549695428,
)
ICUB = ShippedHead(
    file="icub.xml",
    head_body="head_center",
    cameras=("l_eye_camera", "r_eye_camera"),
    pans=("l_eye_pan", "r_eye_pan"),
    neck_yaw="neck_yaw",
    neck_pitch="neck_pitch",
    baseline_m=0.068,  # iKinFwd.cpp: the eyes at D = -/+ 0.034 m on the tilt axis
    resolution=(320, 240),  # icubSimEyes.ini
    focal_px=257.34,  # icubSimEyes.ini
)
HEADS = [pytest.param(INDEPENDENT_EYES, id="independent_eyes"), pytest.param(ICUB, id="icub")]

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


def load(head: ShippedHead) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(MODELS_DIR / head.file))


def posed(model: mujoco.MjModel, **angles_rad: float) -> mujoco.MjData:
    """Data at the home keyframe with the named joints set, kinematics computed."""
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    for joint, angle in angles_rad.items():
        data.qpos[model.joint(joint).qposadr[0]] = angle
    mujoco.mj_forward(model, data)
    return data


def w_from_h(model: mujoco.MjModel, data: mujoco.MjData, head: ShippedHead) -> np.ndarray:
    return data.xmat[model.body(head.head_body).id].reshape(3, 3).copy()


def w_from_opencv_camera(data: mujoco.MjData, model: mujoco.MjModel, camera: str) -> np.ndarray:
    return data.cam_xmat[model.camera(camera).id].reshape(3, 3) @ MUJOCO_FROM_OPENCV


def joint_axis_w(model: mujoco.MjModel, data: mujoco.MjData, joint: str) -> np.ndarray:
    return data.xaxis[model.joint(joint).id].copy()


def rot_z(angle_rad: float) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize("head", HEADS)
def test_compiles_standalone_with_every_element_named_once(head: ShippedHead) -> None:
    model = load(head)
    for kind, count in NAMED_KINDS.items():
        first = 1 if kind == mujoco.mjtObj.mjOBJ_BODY else 0  # body 0 is the world
        names = [mujoco.mj_id2name(model, kind, i) for i in range(first, getattr(model, count))]
        assert all(names), f"an unnamed {kind.name}: {names}"
        assert len(set(names)) == len(names), f"a {kind.name} name repeats: {names}"
    home = model.key("home")
    assert model.nkey == 1
    assert np.array_equal(home.qpos, np.zeros(model.nq))
    assert np.array_equal(home.ctrl, np.zeros(model.nu))
    # Every motor is a position servo: gain kp on the target, -kp on the length.
    assert np.all(model.actuator_gaintype == mujoco.mjtGain.mjGAIN_FIXED)
    assert np.all(model.actuator_biasprm[:, 1] == -model.actuator_gainprm[:, 0])
    # Every moving body is gravity-compensated and has a mass.
    moving = [
        b for b in range(1, model.nbody) if model.body_weldid[b] != 0
    ]  # not welded to the world
    assert moving
    assert all(model.body_gravcomp[b] == 1.0 and model.body_mass[b] > 0 for b in moving)


@pytest.mark.parametrize("head", HEADS)
def test_visual_geoms_are_group_3_and_never_collide(head: ShippedHead) -> None:
    model = load(head)
    assert model.ngeom > 0
    assert np.all(model.geom_group == 3)
    assert np.all(model.geom_contype == 0)
    assert np.all(model.geom_conaffinity == 0)


def test_independent_eyes_has_no_coupling_and_none_of_head_xmls_names() -> None:
    model = load(INDEPENDENT_EYES)
    paper = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "head.xml"))
    assert model.neq == 0
    assert model.nu == 4
    for kind, count in NAMED_KINDS.items():
        if kind in (mujoco.mjtObj.mjOBJ_GEOM, mujoco.mjtObj.mjOBJ_KEY):
            continue  # visual geoms may share names; "home" is every head's keyframe
        ours = {mujoco.mj_id2name(model, kind, i) for i in range(getattr(model, count))}
        theirs = {mujoco.mj_id2name(paper, kind, i) for i in range(getattr(paper, count))}
        assert not (ours & theirs) - {"world"}, kind.name
    # Each eye motor drives its own pan joint, and nothing else.
    for motor, joint in (("left_eye_motor", "left_eye_pan"), ("right_eye_motor", "right_eye_pan")):
        actuator = model.actuator(motor)
        assert actuator.trntype[0] == mujoco.mjtTrn.mjTRN_JOINT
        assert actuator.trnid[0] == model.joint(joint).id


def test_independent_eyes_keeps_the_papers_neck_and_cameras() -> None:
    model = load(INDEPENDENT_EYES)
    paper = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "head.xml"))
    for yaw, pitch in ((0.0, 0.0), (0.4, -0.3)):
        ours = posed(model, neck_yaw_joint=yaw, neck_pitch_joint=pitch)
        theirs = posed(paper, neck_yaw=yaw, neck_pitch=pitch)
        assert np.allclose(
            ours.xpos[model.body("head_frame").id],
            theirs.xpos[paper.body("head").id],
            rtol=0,
            atol=TIGHT,
        )
        assert np.allclose(
            ours.xmat[model.body("head_frame").id],
            theirs.xmat[paper.body("head").id],
            rtol=0,
            atol=TIGHT,
        )
        assert np.allclose(ours.cam_xpos, theirs.cam_xpos, rtol=0, atol=TIGHT)
    assert np.array_equal(model.cam_resolution, paper.cam_resolution)
    assert np.array_equal(model.cam_intrinsic, paper.cam_intrinsic)


@pytest.mark.parametrize("head", HEADS)
def test_at_home_h_is_midway_between_the_cameras_with_hs_axes(head: ShippedHead) -> None:
    model = load(head)
    data = posed(model)
    w_from_h_home = w_from_h(model, data, head)
    origin_w = data.xpos[model.body(head.head_body).id]
    left_w, right_w = (data.cam_xpos[model.camera(c).id] for c in head.cameras)
    assert np.allclose(w_from_h_home, W_FROM_H_HOME, rtol=0, atol=TIGHT)
    assert np.allclose(origin_w, (left_w + right_w) / 2, rtol=0, atol=TIGHT)
    half = head.baseline_m / 2
    for camera, x_h in zip(head.cameras, (-half, half), strict=True):
        centre_h = w_from_h_home.T @ (data.cam_xpos[model.camera(camera).id] - origin_w)
        assert np.allclose(centre_h, [x_h, 0.0, 0.0], rtol=0, atol=TIGHT)
        # OpenCV-aligned with H: the optical axis (OpenCV z) is H's z, u along H's x.
        assert np.allclose(
            w_from_opencv_camera(data, model, camera), w_from_h_home, rtol=0, atol=TIGHT
        )


@pytest.mark.parametrize("head", HEADS)
def test_cameras_are_ideal_pinholes_with_the_cited_intrinsics(head: ShippedHead) -> None:
    model = load(head)
    width, height = head.resolution
    for camera in head.cameras:
        cid = model.camera(camera).id
        resolution = model.cam_resolution[cid]
        assert tuple(resolution) == (width, height)
        intrinsic = model.cam_intrinsic[cid]  # focal lengths and principal offset, in length
        focal_px = intrinsic[:2] / model.cam_sensorsize[cid] * resolution
        # MjModel stores sensor sizes and intrinsics as float32: 1e-7 relative.
        assert np.allclose(focal_px, head.focal_px, rtol=1e-6, atol=0)
        assert np.array_equal(intrinsic[2:], [0.0, 0.0])  # principal point at the centre
        vertical_fov_deg = np.degrees(2 * np.arctan(height / 2 / head.focal_px))
        assert model.cam_fovy[cid] == pytest.approx(vertical_fov_deg, abs=1e-5)


@pytest.mark.parametrize("head", HEADS)
def test_pan_axes_are_hs_y_through_each_camera_and_square_to_the_baseline(
    head: ShippedHead,
) -> None:
    model = load(head)
    data = posed(model)
    w_from_h_home = w_from_h(model, data, head)
    left, right = (joint_axis_w(model, data, j) for j in head.pans)
    assert np.allclose(left, w_from_h_home[:, 1], rtol=0, atol=TIGHT)  # H's +y
    assert np.allclose(right, -w_from_h_home[:, 1], rtol=0, atol=TIGHT)  # H's -y
    baseline_w = (
        data.cam_xpos[model.camera(head.cameras[1]).id]
        - data.cam_xpos[model.camera(head.cameras[0]).id]
    )
    assert np.linalg.norm(baseline_w) == pytest.approx(head.baseline_m, abs=TIGHT)
    assert abs(left @ baseline_w) < TIGHT
    for joint, camera in zip(head.pans, head.cameras, strict=True):
        anchor_w = data.xanchor[model.joint(joint).id]
        assert np.allclose(anchor_w, data.cam_xpos[model.camera(camera).id], rtol=0, atol=TIGHT)


@pytest.mark.parametrize("head", HEADS)
@pytest.mark.parametrize("side", [0, 1], ids=["left", "right"])
def test_a_positive_pan_turns_that_camera_inward_about_its_centre(
    head: ShippedHead, side: int
) -> None:
    model = load(head)
    home = posed(model)
    turned = posed(model, **{head.pans[side]: 0.1})
    w_from_h_home = w_from_h(model, home, head)
    inward = 1.0 if side == 0 else -1.0  # left turns towards H's +x, right towards -x
    for other in (0, 1):
        camera = head.cameras[other]
        axis_h = w_from_h_home.T @ w_from_opencv_camera(turned, model, camera)[:, 2]
        expected = [inward * np.sin(0.1), 0.0, np.cos(0.1)] if other == side else [0.0, 0.0, 1.0]
        assert np.allclose(axis_h, expected, rtol=0, atol=TIGHT)
        cid = model.camera(camera).id
        assert np.allclose(turned.cam_xpos[cid], home.cam_xpos[cid], rtol=0, atol=TIGHT)


@pytest.mark.parametrize("head", HEADS)
def test_neck_yaw_turns_the_head_about_world_z(head: ShippedHead) -> None:
    model = load(head)
    home = posed(model)
    yawed = posed(model, **{head.neck_yaw: 0.3})
    hid = model.body(head.head_body).id
    assert np.allclose(
        joint_axis_w(model, home, head.neck_yaw), [0.0, 0.0, 1.0], rtol=0, atol=TIGHT
    )
    assert np.allclose(
        yawed.xmat[hid].reshape(3, 3), rot_z(0.3) @ W_FROM_H_HOME, rtol=0, atol=TIGHT
    )
    assert np.allclose(yawed.xpos[hid], rot_z(0.3) @ home.xpos[hid], rtol=0, atol=TIGHT)
    # Positive yaw turns the gaze to the left (towards W's -x).
    assert yawed.xmat[hid].reshape(3, 3)[0, 2] < -0.29


@pytest.mark.parametrize("head", HEADS)
def test_positive_neck_pitch_looks_up_about_world_x(head: ShippedHead) -> None:
    model = load(head)
    home = posed(model)
    assert np.allclose(
        joint_axis_w(model, home, head.neck_pitch), [1.0, 0.0, 0.0], rtol=0, atol=TIGHT
    )
    pitched = posed(model, **{head.neck_pitch: 0.2})
    forward_w = pitched.xmat[model.body(head.head_body).id].reshape(3, 3)[:, 2]
    assert np.allclose(forward_w, [0.0, np.cos(0.2), np.sin(0.2)], rtol=0, atol=TIGHT)


def test_icub_neck_pitch_roll_yaw_chain_and_its_offsets() -> None:
    """iKinFwd.cpp (v2): roll 9.5 mm above pitch, yaw through roll, H 50.9 mm ahead, 91.55 mm up."""
    model = load(ICUB)
    data = posed(model)
    assert [model.joint(j).id for j in ("neck_pitch", "neck_roll", "neck_yaw")] == [0, 1, 2]
    assert np.allclose(
        data.xanchor[model.joint("neck_pitch").id], [0.0, 0.0, 0.0], rtol=0, atol=TIGHT
    )
    assert np.allclose(joint_axis_w(model, data, "neck_roll"), [0.0, 1.0, 0.0], rtol=0, atol=TIGHT)
    assert np.allclose(
        data.xanchor[model.joint("neck_roll").id], [0.0, 0.0, 0.0095], rtol=0, atol=TIGHT
    )
    assert np.allclose(
        data.xanchor[model.joint("neck_yaw").id], [0.0, 0.0, 0.0095], rtol=0, atol=TIGHT
    )
    assert np.allclose(
        data.xpos[model.body("head_center").id], [0.0, 0.0509, 0.09155], rtol=0, atol=TIGHT
    )
    # Positive roll tips the head's top (H's -y) to the right, about the forward axis.
    rolled = posed(model, neck_roll=0.2)
    up_w = -rolled.xmat[model.body("head_center").id].reshape(3, 3)[:, 1]
    assert np.allclose(up_w, [np.sin(0.2), 0.0, np.cos(0.2)], rtol=0, atol=TIGHT)


def test_icub_eyes_tilt_is_about_the_baseline_and_positive_looks_up() -> None:
    model = load(ICUB)
    home = posed(model)
    tilted = posed(model, eyes_tilt=0.2)
    w_from_h_home = w_from_h(model, home, ICUB)
    assert np.allclose(
        joint_axis_w(model, home, "eyes_tilt"), w_from_h_home[:, 0], rtol=0, atol=TIGHT
    )
    # The axis is the baseline: tilting moves neither optical centre, nor H.
    assert np.allclose(tilted.cam_xpos, home.cam_xpos, rtol=0, atol=TIGHT)
    assert np.allclose(w_from_h(model, tilted, ICUB), w_from_h_home, rtol=0, atol=TIGHT)
    for camera in ICUB.cameras:
        axis_w = w_from_opencv_camera(tilted, model, camera)[:, 2]
        assert np.allclose(axis_w, [0.0, np.cos(0.2), np.sin(0.2)], rtol=0, atol=TIGHT)
    # The pans tilt with the eyes: their axes stay square to the optical axis.
    pan_w = joint_axis_w(model, tilted, "l_eye_pan")
    assert abs(pan_w @ w_from_opencv_camera(tilted, model, "l_eye_camera")[:, 2]) < TIGHT


def test_icub_version_and_vergence_tendons_are_the_stated_pan_combinations() -> None:
    model = load(ICUB)
    version, vergence = model.tendon("eyes_version").id, model.tendon("eyes_vergence").id
    for left, right in ((0.2, 0.1), (0.1, -0.1), (-0.3, 0.05)):
        data = posed(model, l_eye_pan=left, r_eye_pan=right)
        assert data.ten_length[version] == pytest.approx((left - right) / 2, abs=TIGHT)
        assert data.ten_length[vergence] == pytest.approx(left + right, abs=TIGHT)
    for motor, tendon in (
        ("eyes_version_motor", "eyes_version"),
        ("eyes_vergence_motor", "eyes_vergence"),
    ):
        actuator = model.actuator(motor)
        assert actuator.trntype[0] == mujoco.mjtTrn.mjTRN_TENDON
        assert actuator.trnid[0] == model.tendon(tendon).id


def settle(model: mujoco.MjModel, ctrl: dict[str, float], seconds: float = 2.0) -> mujoco.MjData:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    for motor, target in ctrl.items():
        data.ctrl[model.actuator(motor).id] = target
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return data


def test_icub_version_turns_both_eyes_one_way_and_vergence_turns_them_inward() -> None:
    model = load(ICUB)
    left, right = (model.joint(j).qposadr[0] for j in ICUB.pans)

    def optical_axes_x_h(data: mujoco.MjData) -> list[float]:
        w_from_h_now = w_from_h(model, data, ICUB)
        return [
            (w_from_h_now.T @ w_from_opencv_camera(data, model, c)[:, 2])[0] for c in ICUB.cameras
        ]

    turned = settle(model, {"eyes_version_motor": 0.2})
    assert turned.qpos[left] == pytest.approx(0.2, abs=1e-6)
    assert turned.qpos[right] == pytest.approx(-0.2, abs=1e-6)
    # Both optical axes turn the same way, about H's +y: towards H's +x.
    assert optical_axes_x_h(turned) == pytest.approx([np.sin(0.2)] * 2, abs=1e-6)

    verged = settle(model, {"eyes_vergence_motor": 0.3})
    assert verged.qpos[left] == pytest.approx(0.15, abs=1e-6)
    assert verged.qpos[right] == pytest.approx(0.15, abs=1e-6)
    # Opposite ways: each inward, the left towards +x, the right towards -x.
    assert optical_axes_x_h(verged) == pytest.approx([np.sin(0.15), -np.sin(0.15)], abs=1e-6)

    both = settle(model, {"eyes_version_motor": 0.1, "eyes_vergence_motor": 0.2})
    assert both.qpos[left] == pytest.approx(0.1 + 0.2 / 2, abs=1e-6)
    assert both.qpos[right] == pytest.approx(0.2 / 2 - 0.1, abs=1e-6)


def test_independent_eyes_motors_turn_one_eye_each() -> None:
    model = load(INDEPENDENT_EYES)
    data = settle(model, {"left_eye_motor": 0.2, "right_eye_motor": -0.05})
    assert data.qpos[model.joint("left_eye_pan").qposadr[0]] == pytest.approx(0.2, abs=1e-6)
    assert data.qpos[model.joint("right_eye_pan").qposadr[0]] == pytest.approx(-0.05, abs=1e-6)


# --- Rendering ------------------------------------------------------------------------------

SPHERE_DISTANCE_M = 0.5
SPHERE_RADIUS_M = 0.01


def with_sphere_ahead_of(head: ShippedHead, camera: str) -> mujoco.MjModel:
    """The head file with a bright emissive red sphere on the camera's optical axis at home."""
    home = posed(load(head))
    ahead_w = w_from_opencv_camera(home, load(head), camera)[:, 2]
    centre_w = home.cam_xpos[load(head).camera(camera).id] + SPHERE_DISTANCE_M * ahead_w
    spec = mujoco.MjSpec.from_file(str(MODELS_DIR / head.file))
    spec.add_material(name="test_red", rgba=[1.0, 0.0, 0.0, 1.0], emission=1.0)
    body = spec.worldbody.add_body(name="test_target", pos=centre_w)
    body.add_geom(
        name="test_sphere",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[SPHERE_RADIUS_M, 0.0, 0.0],
        material="test_red",
        contype=0,
        conaffinity=0,
    )
    return spec.compile()


def red_centroid(image: np.ndarray) -> tuple[float, float, int]:
    """(u, v) of the red blob's pixel centres, OpenCV pixel coordinates, and its pixel count."""
    red = (image[..., 0] > 200) & (image[..., 1] < 60) & (image[..., 2] < 60)
    v, u = np.nonzero(red)
    return float(u.mean()), float(v.mean()), int(red.sum())


@pytest.mark.parametrize("head", HEADS)
@pytest.mark.parametrize("side", [0, 1], ids=["left", "right"])
def test_a_sphere_on_the_optical_axis_renders_at_the_image_centre_and_moves_when_the_eye_turns(
    head: ShippedHead, side: int
) -> None:
    camera, pan = head.cameras[side], head.pans[side]
    model = with_sphere_ahead_of(head, camera)
    width, height = head.resolution
    centre_u, centre_v = (width - 1) / 2, (height - 1) / 2
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        renderer.update_scene(posed(model), camera=camera)
        u, v, pixels = red_centroid(renderer.render())
        expected_radius_px = head.focal_px * SPHERE_RADIUS_M / SPHERE_DISTANCE_M
        assert pixels == pytest.approx(np.pi * expected_radius_px**2, rel=0.25)  # edges antialiased
        assert (u, v) == pytest.approx((centre_u, centre_v), abs=0.25)
        # Turned inward by 0.1 rad, the eye sees the sphere move outward in its image:
        # the left eye turns right, so the sphere moves left (u falls), and vice versa.
        renderer.update_scene(posed(model, **{pan: 0.1}), camera=camera)
        u_turned, v_turned, _ = red_centroid(renderer.render())
    shift_px = head.focal_px * np.tan(0.1)
    expected_u = centre_u - shift_px if side == 0 else centre_u + shift_px
    assert u_turned == pytest.approx(expected_u, abs=0.25)
    assert v_turned == pytest.approx(centre_v, abs=0.25)


# --- With the project's scene props ----------------------------------------------------------

PREFIX = "head/"  # MjSpec warns on an empty attach prefix


def in_default_scene(head: ShippedHead) -> mujoco.MjModel:
    """models/scene.xml with the paper head swapped for this one (attached at W's origin)."""
    scene = mujoco.MjSpec.from_file(str(MODELS_DIR / "scene.xml"))
    for element in [*scene.actuators, *scene.equalities, *scene.keys]:
        scene.delete(element)
    scene.delete(scene.body("neck_base"))  # the paper head, its joints, geoms and cameras
    spec = mujoco.MjSpec.from_file(str(MODELS_DIR / head.file))
    scene.worldbody.add_frame().attach_body(spec.worldbody.first_body(), PREFIX, "")
    return scene.compile()


@pytest.mark.parametrize("head", HEADS)
def test_in_the_default_scene_a_marker_renders_where_the_pinhole_puts_it(head: ShippedHead) -> None:
    model = in_default_scene(head)
    alone = posed(load(head))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(PREFIX + "home").id)
    mujoco.mj_forward(model, data)
    # The head sits where it sits alone, and keeps its motors and tendons.
    hid = model.body(PREFIX + head.head_body).id
    assert np.allclose(
        data.xpos[hid], alone.xpos[load(head).body(head.head_body).id], rtol=0, atol=TIGHT
    )
    assert model.nu == load(head).nu and model.ntendon == load(head).ntendon
    marker_w = data.xpos[model.body("marker_red").id]
    width, height = head.resolution
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        for camera in head.cameras:
            cid = model.camera(PREFIX + camera).id
            renderer.update_scene(data, camera=cid)
            u, v, pixels = red_centroid(renderer.render())
            x, y, z = w_from_opencv_camera(data, model, PREFIX + camera).T @ (
                marker_w - data.cam_xpos[cid]
            )
            assert pixels > 5
            expected = (
                (width - 1) / 2 + head.focal_px * x / z,
                (height - 1) / 2 + head.focal_px * y / z,
            )
            assert (u, v) == pytest.approx(expected, abs=0.5)
