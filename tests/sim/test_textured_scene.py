"""Generated textures reach MuJoCo's images where they should: a plane seen head-on
shows its texture upright at the expected scale, and a room is built around the head
without changing it.  Real rendering."""

from __future__ import annotations

import math
from dataclasses import replace

import cv2
import mujoco
import numpy as np
import pytest

from headsim.sim import names
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.sim.textured_scene import LightSettings, RoomSpec, SceneObject, add_object
from headsim.sim.textures import TextureSpec, texture_grey

WIDTH, HEIGHT, FOVY_DEG, HEIGHT_M = 320, 240, 60.0, 1.0


def _render_from_above(obj: SceneObject) -> np.ndarray:
    """``obj`` alone, lit by an ambient headlight only, seen straight down from
    ``HEIGHT_M`` above W's origin (image right: W's +x, image up: W's +y); grey."""
    spec = mujoco.MjSpec()
    spec.visual.headlight.active = 1
    spec.visual.headlight.ambient = [1.0, 1.0, 1.0]
    spec.visual.headlight.diffuse = [0.0, 0.0, 0.0]
    spec.visual.global_.offwidth, spec.visual.global_.offheight = WIDTH, HEIGHT
    add_object(spec, obj)
    spec.worldbody.add_camera(name="down", pos=[0.0, 0.0, HEIGHT_M], fovy=FOVY_DEG)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    with mujoco.Renderer(model, HEIGHT, WIDTH) as renderer:
        renderer.update_scene(data, "down")
        rgb = renderer.render()
    return cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(float)


def _plane(texture: TextureSpec, half_m: float, tile_m: float) -> SceneObject:
    return SceneObject("plane", "plane", (half_m, half_m, 1.0), (0.0, 0.0, 0.0), texture,
                       tile_m=tile_m)  # fmt: skip


F_PX = (HEIGHT / 2) / math.tan(math.radians(FOVY_DEG) / 2)
CX, CY = (WIDTH - 1) / 2, (HEIGHT - 1) / 2


def test_a_textured_plane_shows_its_texture_upright_and_at_scale() -> None:
    """Pixel (u, v) sees W's (x, y) = ((u - cx), -(v - cy)) h / f; the texture's column j
    runs along +x from the plane's -x edge and its row 0 lies at the +y edge."""
    half = 0.3
    texture = TextureSpec("pink", seed=5, size_px=128)
    image = _render_from_above(_plane(texture, half, 2 * half))
    grey = texture_grey(texture)
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(float)
    x, y = (u - CX) * HEIGHT_M / F_PX, -(v - CY) * HEIGHT_M / F_PX
    n = texture.size_px
    map_x = ((x + half) / (2 * half) * n - 0.5).astype(np.float32)
    map_y = ((half - y) / (2 * half) * n - 0.5).astype(np.float32)
    expected = cv2.remap(grey.astype(np.float32), map_x, map_y, cv2.INTER_LINEAR)
    inside = (np.abs(x) < half - 0.01) & (np.abs(y) < half - 0.01)
    r = np.corrcoef(image[inside], expected[inside])[0, 1]
    assert r > 0.99  # 0.9998 here
    # The same texture flipped left-right or upside down does not match.
    for flipped in (expected[:, ::-1], expected[::-1, :]):
        assert np.corrcoef(image[inside], flipped[inside])[0, 1] < 0.3


def test_a_grating_on_a_plane_repeats_at_its_period_in_the_image() -> None:
    """A vertical grating of 16 texture px per period, 256 px to a 0.6 m tile: a period
    of 37.5 mm on the plane, f * 0.0375 / h px in the image."""
    texture = TextureSpec("grating", seed=1, size_px=256, period_px=16.0)
    image = _render_from_above(_plane(texture, 0.3, 0.6))
    rows = image[70:170, 104:216]  # inside the plane (|x|, |y| < 0.27 m)
    profile = rows.mean(axis=0) - rows.mean()
    spectrum = np.abs(np.fft.rfft(profile * np.hanning(len(profile))))
    spectrum[0] = 0.0
    k = int(spectrum.argmax())
    # Parabolic interpolation of the peak: the period to a fraction of a bin.
    a, b, c = np.log(spectrum[k - 1 : k + 2])
    peak = k + 0.5 * (a - c) / (a - 2 * b + c)
    period_px = len(profile) / peak
    assert period_px == pytest.approx(F_PX * 0.0375 / HEIGHT_M, rel=0.01)


def _room() -> RoomSpec:
    panel = SceneObject(
        "panel", "plane", (0.3, 0.2, 1.0), (0.0, 1.0, 0.2), TextureSpec("pink", seed=3),
        pitch_rad=math.pi / 2, tile_m=0.3,
    )  # fmt: skip
    return RoomSpec(seed=2, objects=(panel,))


def test_a_room_leaves_the_head_as_it_is_and_replaces_only_table_and_light() -> None:
    settings = HeadSettings()
    with HeadSim("default", settings) as bare, HeadSim("default", settings, room=_room()) as room:
        for body in (names.HEAD, *names.EYE_BODIES, names.NECK_BASE):
            np.testing.assert_array_equal(bare.data.body(body).xpos, room.data.body(body).xpos)
        for camera in (1, 2):
            np.testing.assert_array_equal(
                bare.world_from_camera(camera), room.world_from_camera(camera)
            )
        head = [g for g in range(bare.model.ngeom) if bare.model.geom_group[g] == 3]
        assert len(head) == sum(room.model.geom_group == 3)
        assert mujoco.mj_name2id(room.model, mujoco.mjtObj.mjOBJ_GEOM, names.TABLE_PLANE) < 0
        for name in (names.ROOM_FLOOR, names.ROOM_TABLE, *names.ROOM_WALLS, "panel"):
            assert mujoco.mj_name2id(room.model, mujoco.mjtObj.mjOBJ_GEOM, name) >= 0
        # The markers are still there, and the panel fills camera 1's view with texture.
        assert mujoco.mj_name2id(room.model, mujoco.mjtObj.mjOBJ_BODY, names.MARKERS[0]) >= 0
        window = room.render(1)[200:280, 280:360]
        assert np.median(bare.render(1)[200:280, 280:360]) < 5  # a dark room, a marker
        assert np.median(window) > 20 and window.std() > 5


def test_the_light_settings_reach_the_model_and_the_image() -> None:
    dim = RoomSpec(objects=_room().objects, light=LightSettings(diffuse=0.1, ambient=0.1))
    bright = RoomSpec(objects=_room().objects, light=LightSettings(diffuse=0.8, ambient=0.4))
    shadows = RoomSpec(objects=_room().objects, light=LightSettings(shadows=True))
    settings = HeadSettings()
    with (
        HeadSim("default", settings, room=dim) as a,
        HeadSim("default", settings, room=bright) as b,
    ):
        assert b.render(1).mean() > a.render(1).mean() + 40
        light = b.model.light(names.KEY_LIGHT)
        assert not bool(light.castshadow)
        assert float(b.model.light_diffuse[light.id][0]) == pytest.approx(0.8)
    with HeadSim("default", settings, room=shadows) as s:
        assert bool(s.model.light(names.KEY_LIGHT).castshadow)
        assert int(s.model.vis.quality.shadowsize) > 0
        # The same room's textures without shadows were drawn first: the shadowed one
        # still gets a context with a shadow map (the pool keys on it), and its panel
        # casts a shadow on the table below it.
        s.move(neck_pitch=-0.4)
        with HeadSim("default", settings, room=replace(shadows, light=LightSettings())) as flat:
            flat.move(neck_pitch=-0.4)
            darker = flat.render(1).astype(float).mean() - s.render(1).astype(float).mean()
        assert darker > 0.5


def test_every_surface_of_the_room_faces_into_it() -> None:
    """Rays from the head out to each side meet that side's surface (MuJoCo meets, and
    draws, a plane from its front only)."""
    from headsim.scenario.surface_targets import cast

    room = RoomSpec()
    with HeadSim("default", HeadSettings(), room=room) as sim:
        origin = sim.world_from_head()[:3, 3]
        expected = {
            (0.0, 1.0, 0.0): (names.ROOM_WALLS[0], 1, room.back_wall_y_m),
            (-1.0, 0.0, 0.0): (names.ROOM_WALLS[1], 0, -room.side_wall_x_m),
            (1.0, 0.0, 0.0): (names.ROOM_WALLS[2], 0, room.side_wall_x_m),
            (0.0, -0.5, -1.0): (names.ROOM_FLOOR, 2, room.floor_z_m),
            (0.0, 1.0, -0.3): (names.ROOM_TABLE, 2, room.table_top_z_m),
        }
        for direction, (name, axis, value) in expected.items():
            point, _, geom = cast(sim.model, sim.data, origin, np.array(direction))
            assert geom >= 0 and sim.model.geom(geom).name == name, direction
            assert point is not None and point[axis] == pytest.approx(value, abs=1e-9)
