"""Bad settings and a missing OpenGL backend fail early with a message naming the problem."""

from __future__ import annotations

import ctypes.util
import os
import subprocess
import sys
from typing import Any

import pytest

from headsim.sim import imperfections
from headsim.sim.declared import Setting
from headsim.sim.settings import (
    BELIEF_SETTINGS,
    CAMERA_SETTINGS,
    COUNT_ERROR,
    HEAD_SETTINGS,
    NODAL_OFFSET,
    PRESETS,
    RENDER_SETTINGS,
    CameraSettings,
    HeadSettings,
    SettingsError,
    paper_head,
    preset,
    settings_record,
)
from headsim.sim.simulator import HeadSim


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (
            lambda: HeadSettings(baseline_m=-0.15),
            r"baseline_m must be within \[0.01, 1\] m, got -0.15",
        ),
        (lambda: HeadSettings(baseline_m=float("nan")), "baseline_m must be a finite number"),
        (lambda: CameraSettings(width=5000), r"width must be within \[16, 4096\] px, got 5000"),
        (lambda: CameraSettings(height=0), r"height must be within \[16, 4096\] px, got 0"),
        (lambda: CameraSettings(height=240.0), "height must be an integer, got 240.0"),
        (lambda: CameraSettings(kx=-5.0), r"kx must be within \[1, 100000\] px, got -5.0"),
        (
            lambda: CameraSettings(mount_roll_rad=0.5),
            r"mount_roll_rad must be within \(-0.5, 0.5\)",
        ),
        (lambda: CameraSettings(cx=700.0), "principal point cx = 700.0 px lies outside the image"),
        (lambda: CameraSettings(noise_std=-1.0), r"noise_std must be within \[0, 50\] grey levels"),
        (
            lambda: HeadSettings(encoder_resolution_rad=0.0),
            r"encoder_resolution_rad must be within \(0, 0.01\] rad, got 0.0",
        ),
        (lambda: HeadSettings(neck_d1_m=float("nan")), "neck_d1_m must be a finite number"),
        (lambda: HeadSettings(cameras=(CameraSettings(),)), "cameras must be a pair"),
        (lambda: preset("fisheye"), "unknown preset 'fisheye'; allowed: ideal, paper"),
    ],
)
def test_bad_settings_name_the_field(make, message: str) -> None:
    with pytest.raises(SettingsError, match=message):
        make()


@pytest.mark.parametrize("setting", CAMERA_SETTINGS, ids=lambda s: s.name)
def test_each_camera_setting_is_checked_by_its_declaration(setting: Setting) -> None:
    """CameraSettings takes its defaults from the declaration and refuses just past either
    end of the declared range, naming the setting."""
    camera = CameraSettings()
    assert getattr(camera, setting.name) == setting.default
    assert setting.meaning and setting.name in CameraSettings.__dataclass_fields__
    step = 1 if setting.integer else 1e-9 * max(1.0, abs(setting.hi))
    for outside in (setting.lo - step, setting.hi + step):
        with pytest.raises(SettingsError, match=f"^{setting.name} must be within"):
            bad: dict[str, Any] = {setting.name: type(setting.lo)(outside)}
            CameraSettings(**bad)


@pytest.mark.parametrize("setting", HEAD_SETTINGS, ids=lambda s: s.name)
def test_each_head_setting_is_checked_by_its_declaration(setting: Setting) -> None:
    """HeadSettings takes its defaults from the declaration and refuses just past either end
    of the declared range (an open end: the end itself), naming the setting."""
    assert getattr(HeadSettings(), setting.name) == setting.default and setting.meaning
    step = 1e-9 * max(1.0, abs(setting.hi))
    lo = setting.lo if setting.lo_open else setting.lo - step
    for outside in (lo, setting.hi + step):
        with pytest.raises(SettingsError, match=f"^{setting.name} must be within"):
            bad: dict[str, Any] = {setting.name: outside}
            HeadSettings(**bad)


@pytest.mark.parametrize("name", PRESETS)
def test_every_value_the_settings_record_holds_is_a_declared_settings(name: str) -> None:
    """results.json's settings block records declared settings only (beside its structure:
    the cameras, seed, belief and render tables), each under its declared name."""
    record = settings_record(preset(name))
    structure = {"cameras", "seed", "belief", "render"}
    assert set(record) - structure == {s.name for s in (*HEAD_SETTINGS, COUNT_ERROR)}
    camera_names = {s.name for s in (*CAMERA_SETTINGS, *imperfections.all_settings())}
    assert all(set(camera) == camera_names for camera in record["cameras"])
    assert {f"render_{key}" for key in record["render"]} == {s.name for s in RENDER_SETTINGS}
    belief = record["belief"]
    believed = {s.name for s in BELIEF_SETTINGS} | {NODAL_OFFSET.name}
    assert belief is None or set(belief) == believed


def test_unknown_scene_lists_the_scenes() -> None:
    with pytest.raises(
        SettingsError, match="unknown scene 'kitchen'; allowed: base, blocks, chessboard, default"
    ):
        HeadSim("kitchen")


def test_zoom_scales_both_focal_lengths() -> None:
    cam = paper_head().cameras[0].with_zoom(1.5)
    assert cam.kx == pytest.approx(834.83 * 1.5)
    assert cam.ky == pytest.approx(815.42 * 1.5)
    assert cam.principal == (303.8, 306.3)


def _render_in_subprocess(backend: str) -> subprocess.CompletedProcess[str]:
    code = (
        "from headsim.sim.simulator import HeadSim\nHeadSim('default').render(1)\nprint('rendered')"
    )
    env = {**os.environ, "MUJOCO_GL": backend}
    return subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )


def test_an_invalid_backend_names_the_allowed_ones() -> None:
    result = _render_in_subprocess("vulkan")
    assert result.returncode != 0
    assert (
        "MUJOCO_GL='vulkan' is not a backend headsim can render with; allowed: egl, osmesa, glfw"
        in result.stderr
    )
    assert "apt-get install" in result.stderr


def test_osmesa_renders_or_says_what_to_install() -> None:
    result = _render_in_subprocess("osmesa")
    if ctypes.util.find_library("OSMesa") is None:
        assert result.returncode != 0
        assert "libOSMesa is not installed" in result.stderr
        assert "apt-get install libosmesa6" in result.stderr
    else:
        assert result.returncode == 0, result.stderr
        assert "rendered" in result.stdout
