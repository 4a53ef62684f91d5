"""Every shipped head (the registry, :data:`headsim.sim.heads.REGISTRY`: the paper's
models/head.xml and each head file that declares itself), with real MuJoCo: its
declaration, frames, axes, signs and cameras.  A head added to models/ is tested here
with no edit; its own numbers (baseline, cameras, neck offsets
as cited) are its own test's, tests/models/test_NAME.py.

Every head keeps the project's frames (docs/equations.md, "Frames and signs"): W at the
neck base (x right, y forward, z up), the head body at H (origin midway between the
optical centres, x right, y down, z forward) at all joints 0, each camera OpenCV-aligned
with H there and on its eye's pan axis, and each pan angle positive inward.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from headsim.sim.head_files import MODELS_DIR, SHIPPED, declaration, declared_heads
from headsim.sim.heads import REGISTRY, HeadMapping, declared_head
from headsim.sim.model import design
from tests.models.mjcf import (
    NAMED_KINDS,
    TIGHT,
    W_FROM_H_HOME,
    head_file,
    joint_axis_w,
    load,
    names,
    posed,
    rot_z,
    w_from_h,
    w_from_opencv_camera,
)

#: Every shipped head.
HEADS = list(REGISTRY)
#: Those with a neck yaw (a head may have none: Model 2 only).
YAWING = [name for name in HEADS if REGISTRY[name].mapping.neck_yaw is not None]


def pans(name: str) -> tuple[str, str]:
    """The eye pan joints: left, right; positive turns the eye inward."""
    return names(name).left_eye, names(name).right_eye


def neck_yaw(name: str) -> str:
    joint = names(name).neck_yaw
    assert joint is not None
    return joint


def focal_px(name: str) -> float:
    """The head's designed focal length, px (both cameras, both axes: checked below)."""
    return design(REGISTRY[name]).cameras[0].fx_px


def resolution(name: str) -> tuple[int, int]:
    camera = design(REGISTRY[name]).cameras[0]
    return camera.width, camera.height


# --- The declaration ---------------------------------------------------------------------


@pytest.mark.fast
def test_every_model_file_is_a_scene_the_papers_head_or_a_declared_head() -> None:
    """A head file dropped into models/ without its declaration would be silently unshipped."""
    for path in sorted(MODELS_DIR.glob("*.xml")):
        if path.stem.startswith("scene") or path.name == "head.xml":
            assert not declaration(path), path.name
            continue
        declared = declaration(path)
        assert path.stem in REGISTRY, path.name
        assert declared["description"] and "\n" not in declared["description"]
        assert {k.removeprefix("mapping.") for k in declared if k != "description"} <= set(
            HeadMapping.__dataclass_fields__
        ), path.name
    assert list(SHIPPED) == list(REGISTRY) and next(iter(SHIPPED)) == "paper"


@pytest.mark.fast
@pytest.mark.parametrize("name", [name for name in HEADS if REGISTRY[name].path is not None])
def test_a_file_that_declares_itself_is_a_head_with_no_other_edit(
    tmp_path: Path, name: str
) -> None:
    """A copy of a head file under a new name, with its own line, is found as a head and
    holds as the original does; a mapping key HeadMapping lacks is refused naming both."""
    text = head_file(name).read_text()
    (tmp_path / "twin.xml").write_text(
        text.replace(f'data="{SHIPPED[name]}"', 'data="a twin, for the test"')
    )
    (tmp_path / "scene_twin.xml").write_text("<mujoco/>")  # declares nothing: not a head
    found = declared_heads(tmp_path)
    assert list(found) == ["twin"] and found["twin"]["description"] == "a twin, for the test"
    twin = declared_head(tmp_path / "twin.xml", found["twin"])
    assert (twin.name, twin.mapping) == ("twin", REGISTRY[name].mapping)
    assert design(twin) == design(REGISTRY[name])
    with pytest.raises(ValueError, match=r"twin\.xml: <custom> headsim:mapping: .*'nose'"):
        declared_head(tmp_path / "twin.xml", {**found["twin"], "mapping.nose": "n"})


@pytest.mark.parametrize("name", HEADS)
def test_the_declared_mapping_holds_against_the_model(name: str) -> None:
    """check_head accepts the file's own mapping: a user could run it as an MJCF head."""
    geometry = design(REGISTRY[name])
    assert geometry.baseline_m > 0 and len(geometry.cameras) == 2
    assert geometry.cameras[0] == geometry.cameras[1]
    camera = geometry.cameras[0]
    assert camera.fx_px == pytest.approx(camera.fy_px, rel=1e-6)
    assert (camera.cx_px, camera.cy_px) == ((camera.width - 1) / 2, (camera.height - 1) / 2)


@pytest.mark.parametrize("name", HEADS)
def test_compiles_standalone_with_every_element_named_once(name: str) -> None:
    model = load(name)
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


@pytest.mark.parametrize("name", HEADS)
def test_visual_geoms_are_group_3_and_never_collide(name: str) -> None:
    model = load(name)
    assert model.ngeom > 0
    assert np.all(model.geom_group == 3)
    assert np.all(model.geom_contype == 0)
    assert np.all(model.geom_conaffinity == 0)


@pytest.mark.parametrize("name", HEADS)
def test_at_home_h_is_midway_between_the_cameras_with_hs_axes(name: str) -> None:
    model = load(name)
    data = posed(model)
    w_from_h_home = w_from_h(model, data, name)
    origin_w = data.xpos[model.body(names(name).head_body).id]
    left_w, right_w = (data.cam_xpos[model.camera(c).id] for c in names(name).cameras)
    assert np.allclose(w_from_h_home, W_FROM_H_HOME, rtol=0, atol=TIGHT)
    assert np.allclose(origin_w, (left_w + right_w) / 2, rtol=0, atol=TIGHT)
    half = design(REGISTRY[name]).baseline_m / 2
    for camera, x_h in zip(names(name).cameras, (-half, half), strict=True):
        centre_h = w_from_h_home.T @ (data.cam_xpos[model.camera(camera).id] - origin_w)
        assert np.allclose(centre_h, [x_h, 0.0, 0.0], rtol=0, atol=TIGHT)
        # OpenCV-aligned with H: the optical axis (OpenCV z) is H's z, u along H's x.
        assert np.allclose(
            w_from_opencv_camera(data, model, camera), w_from_h_home, rtol=0, atol=TIGHT
        )


@pytest.mark.parametrize("name", HEADS)
def test_cameras_are_alike_ideal_pinholes_with_a_consistent_field_of_view(name: str) -> None:
    """Both cameras one size, square pixels, the principal point at the image centre, and
    fovy agreeing with the focal length (what each head cites is its own test's)."""
    model = load(name)
    cids = [model.camera(camera).id for camera in names(name).cameras]
    width, height = (int(v) for v in model.cam_resolution[cids[0]])
    assert min(width, height) >= 32
    for cid in cids:
        assert tuple(model.cam_resolution[cid]) == (width, height)
        intrinsic = model.cam_intrinsic[cid]  # focal lengths and principal offset, in length
        fx_px, fy_px = intrinsic[:2] / model.cam_sensorsize[cid] * model.cam_resolution[cid]
        # MjModel stores sensor sizes and intrinsics as float32: 1e-7 relative.
        assert fy_px == pytest.approx(fx_px, rel=1e-6)
        assert fx_px == pytest.approx(focal_px(name), rel=1e-6)
        assert np.array_equal(intrinsic[2:], [0.0, 0.0])  # principal point at the centre
        vertical_fov_deg = np.degrees(2 * np.arctan(height / 2 / fy_px))
        assert model.cam_fovy[cid] == pytest.approx(vertical_fov_deg, abs=1e-5)


@pytest.mark.parametrize("name", HEADS)
def test_pan_axes_are_hs_y_through_each_camera_and_square_to_the_baseline(
    name: str,
) -> None:
    model = load(name)
    data = posed(model)
    w_from_h_home = w_from_h(model, data, name)
    left, right = (joint_axis_w(model, data, j) for j in pans(name))
    assert np.allclose(left, w_from_h_home[:, 1], rtol=0, atol=TIGHT)  # H's +y
    assert np.allclose(right, -w_from_h_home[:, 1], rtol=0, atol=TIGHT)  # H's -y
    baseline_w = (
        data.cam_xpos[model.camera(names(name).cameras[1]).id]
        - data.cam_xpos[model.camera(names(name).cameras[0]).id]
    )
    assert np.linalg.norm(baseline_w) == pytest.approx(design(REGISTRY[name]).baseline_m, abs=TIGHT)
    assert abs(left @ baseline_w) < TIGHT
    for joint, camera in zip(pans(name), names(name).cameras, strict=True):
        anchor_w = data.xanchor[model.joint(joint).id]
        assert np.allclose(anchor_w, data.cam_xpos[model.camera(camera).id], rtol=0, atol=TIGHT)


@pytest.mark.parametrize("name", HEADS)
@pytest.mark.parametrize("side", [0, 1], ids=["left", "right"])
def test_a_positive_pan_turns_that_camera_inward_about_its_centre(name: str, side: int) -> None:
    model = load(name)
    home = posed(model)
    turned = posed(model, **{pans(name)[side]: 0.1})
    w_from_h_home = w_from_h(model, home, name)
    inward = 1.0 if side == 0 else -1.0  # left turns towards H's +x, right towards -x
    for other in (0, 1):
        camera = names(name).cameras[other]
        axis_h = w_from_h_home.T @ w_from_opencv_camera(turned, model, camera)[:, 2]
        expected = [inward * np.sin(0.1), 0.0, np.cos(0.1)] if other == side else [0.0, 0.0, 1.0]
        assert np.allclose(axis_h, expected, rtol=0, atol=TIGHT)
        cid = model.camera(camera).id
        assert np.allclose(turned.cam_xpos[cid], home.cam_xpos[cid], rtol=0, atol=TIGHT)


@pytest.mark.parametrize("name", YAWING)
def test_neck_yaw_turns_the_head_about_world_z(name: str) -> None:
    model = load(name)
    home = posed(model)
    yawed = posed(model, **{neck_yaw(name): 0.3})
    hid = model.body(names(name).head_body).id
    assert np.allclose(
        joint_axis_w(model, home, neck_yaw(name)), [0.0, 0.0, 1.0], rtol=0, atol=TIGHT
    )
    assert np.allclose(
        yawed.xmat[hid].reshape(3, 3), rot_z(0.3) @ W_FROM_H_HOME, rtol=0, atol=TIGHT
    )
    assert np.allclose(yawed.xpos[hid], rot_z(0.3) @ home.xpos[hid], rtol=0, atol=TIGHT)
    # Positive yaw turns the gaze to the left (towards W's -x).
    assert yawed.xmat[hid].reshape(3, 3)[0, 2] < -0.29


@pytest.mark.parametrize("name", HEADS)
def test_positive_neck_pitch_looks_up_about_world_x(name: str) -> None:
    model = load(name)
    home = posed(model)
    assert np.allclose(
        joint_axis_w(model, home, names(name).neck_pitch), [1.0, 0.0, 0.0], rtol=0, atol=TIGHT
    )
    pitched = posed(model, **{names(name).neck_pitch: 0.2})
    forward_w = pitched.xmat[model.body(names(name).head_body).id].reshape(3, 3)[:, 2]
    assert np.allclose(forward_w, [0.0, np.cos(0.2), np.sin(0.2)], rtol=0, atol=TIGHT)


# --- Rendering ------------------------------------------------------------------------------

SPHERE_DISTANCE_M = 0.5
SPHERE_RADIUS_M = 0.01


def with_sphere_ahead_of(name: str, camera: str) -> mujoco.MjModel:
    """The head file with a bright emissive red sphere on the camera's optical axis at home."""
    home = posed(load(name))
    ahead_w = w_from_opencv_camera(home, load(name), camera)[:, 2]
    centre_w = home.cam_xpos[load(name).camera(camera).id] + SPHERE_DISTANCE_M * ahead_w
    spec = mujoco.MjSpec.from_file(str(head_file(name)))
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


@pytest.mark.parametrize("name", HEADS)
@pytest.mark.parametrize("side", [0, 1], ids=["left", "right"])
def test_a_sphere_on_the_optical_axis_renders_at_the_image_centre_and_moves_when_the_eye_turns(
    name: str, side: int
) -> None:
    camera, pan = names(name).cameras[side], pans(name)[side]
    model = with_sphere_ahead_of(name, camera)
    width, height = resolution(name)
    centre_u, centre_v = (width - 1) / 2, (height - 1) / 2
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        renderer.update_scene(posed(model), camera=camera)
        u, v, pixels = red_centroid(renderer.render())
        expected_radius_px = focal_px(name) * SPHERE_RADIUS_M / SPHERE_DISTANCE_M
        assert pixels == pytest.approx(np.pi * expected_radius_px**2, rel=0.25)  # edges antialiased
        assert (u, v) == pytest.approx((centre_u, centre_v), abs=0.25)
        # Turned inward by 0.1 rad, the eye sees the sphere move outward in its image:
        # the left eye turns right, so the sphere moves left (u falls), and vice versa.
        renderer.update_scene(posed(model, **{pan: 0.1}), camera=camera)
        u_turned, v_turned, _ = red_centroid(renderer.render())
    shift_px = focal_px(name) * np.tan(0.1)
    expected_u = centre_u - shift_px if side == 0 else centre_u + shift_px
    assert u_turned == pytest.approx(expected_u, abs=0.25)
    assert v_turned == pytest.approx(centre_v, abs=0.25)


# --- With the project's scene props ----------------------------------------------------------

PREFIX = "head/"  # MjSpec warns on an empty attach prefix


def in_default_scene(name: str) -> mujoco.MjModel:
    """models/scene.xml with the paper head swapped for this one (attached at W's origin)."""
    scene = mujoco.MjSpec.from_file(str(MODELS_DIR / "scene.xml"))
    for element in [*scene.actuators, *scene.equalities, *scene.keys]:
        scene.delete(element)
    scene.delete(scene.body("neck_base"))  # the paper head, its joints, geoms and cameras
    spec = mujoco.MjSpec.from_file(str(head_file(name)))
    scene.worldbody.add_frame().attach_body(spec.worldbody.first_body(), PREFIX, "")
    return scene.compile()


@pytest.mark.parametrize("name", HEADS)
def test_in_the_default_scene_a_marker_renders_where_the_pinhole_puts_it(name: str) -> None:
    model = in_default_scene(name)
    alone = posed(load(name))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(PREFIX + "home").id)
    mujoco.mj_forward(model, data)
    # The head sits where it sits alone, and keeps its motors and tendons.
    hid = model.body(PREFIX + names(name).head_body).id
    assert np.allclose(
        data.xpos[hid], alone.xpos[load(name).body(names(name).head_body).id], rtol=0, atol=TIGHT
    )
    assert model.nu == load(name).nu and model.ntendon == load(name).ntendon
    marker_w = data.xpos[model.body("marker_red").id]
    width, height = resolution(name)
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        for camera in names(name).cameras:
            cid = model.camera(PREFIX + camera).id
            renderer.update_scene(data, camera=cid)
            u, v, pixels = red_centroid(renderer.render())
            x, y, z = w_from_opencv_camera(data, model, PREFIX + camera).T @ (
                marker_w - data.cam_xpos[cid]
            )
            assert pixels > 5
            expected = (
                (width - 1) / 2 + focal_px(name) * x / z,
                (height - 1) / 2 + focal_px(name) * y / z,
            )
            assert (u, v) == pytest.approx(expected, abs=0.5)
