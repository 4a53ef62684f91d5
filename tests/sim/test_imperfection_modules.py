"""Image imperfections as modules: one added from this test module reaches the classic
renderer, its windows and previews, the batch renderer, the scenario keys and their
reference with no edit elsewhere; and every registered one moves the images it is set on.

Real renders (MuJoCo; MuJoCo Warp on the CPU for the batch renderer).
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from headsim.scenario.key_reference import accepted_keys
from headsim.scenario.loading import load_scenario
from headsim.scenario.tables import ScenarioError
from headsim.sim import imperfections
from headsim.sim.gl_window import Window
from headsim.sim.imperfections import Imperfection, Setting, Shot
from headsim.sim.settings import CameraSettings, HeadSettings, camera_values, settings_record
from headsim.sim.simulator import HeadSim

RAMP = Setting(
    "row_ramp_grey",
    0.0,
    0.0,
    100.0,
    "grey levels",
    "Grey added to the last row, rising from 0 at the first (a test imperfection).",
    example=40.0,
)
RAMP_GREY = 40.0


def _ramp(rows: np.ndarray, grey: float, height: int) -> np.ndarray:
    """The grey that :class:`RowRamp` adds to full-frame rows ``rows``."""
    return np.rint(grey * rows / (height - 1)).astype(np.uint8)


class RowRamp(Imperfection):
    """A grey ramp down the image: what it adds depends on the row of the full frame, so
    a window or a preview gets it right only if it knows where in the frame it lies."""

    name = "test_row_ramp"
    order = 80
    settings = (RAMP,)

    def prepare(self, camera: Any, canvas: Any) -> Any:
        return camera.value(RAMP.name), camera.height

    def active(self, state: Any) -> bool:
        return bool(state[0] > 0)

    def apply(self, image: np.ndarray, state: Any, shot: Shot) -> np.ndarray:
        grey, height = state
        b = shot.binning
        y0 = 0 if shot.window is None else shot.window.y0
        rows = b * (y0 + np.arange(image.shape[0])) + (b - 1) / 2.0  # full-frame rows
        add = _ramp(rows, grey, height)[:, None, None]
        return np.minimum(image.astype(np.int16) + add, 255).astype(np.uint8)


@pytest.fixture
def ramp() -> Iterator[RowRamp]:
    imperfection = RowRamp()
    imperfections.register(imperfection)
    try:
        yield imperfection
    finally:
        imperfections.unregister(imperfection.name)


def _head(grey: float) -> HeadSettings:
    camera = CameraSettings(**camera_values({RAMP.name: grey}))
    return HeadSettings(cameras=(camera, camera))


def _pose(sim: HeadSim) -> None:
    sim.set_body_pose("marker_red", [0.02, 0.6, 0.2])
    sim.move(eye=0.05, neck_yaw=0.03)


def _added(on: np.ndarray, off: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What was added to each row (pixels that did not saturate), and those pixels."""
    unsaturated = off.astype(int) <= 255 - RAMP_GREY
    return on.astype(int) - off.astype(int), unsaturated


def _assert_ramp(on: np.ndarray, off: np.ndarray, rows: np.ndarray) -> None:
    added, unsaturated = _added(on, off)
    expected = np.broadcast_to(_ramp(rows, RAMP_GREY, 480)[:, None, None], added.shape)
    assert unsaturated.mean() > 0.5
    np.testing.assert_array_equal(added[unsaturated], expected[unsaturated])
    assert added[unsaturated].max() >= 10  # it moved the image, by many grey levels


def test_an_imperfection_from_a_test_module_reaches_the_classic_renderer_windows_and_previews(
    ramp: RowRamp,
) -> None:
    window = Window(300, 200, 77, 61)
    images = {}
    for grey in (0.0, RAMP_GREY):
        with HeadSim("default", _head(grey)) as sim:
            _pose(sim)
            images[grey] = (
                sim.render(1),
                sim.render_window(2, window),
                sim.render_preview(1, 4),
            )
    (full_off, window_off, preview_off), (full_on, window_on, preview_on) = images.values()
    _assert_ramp(full_on, full_off, np.arange(480))
    _assert_ramp(window_on, window_off, np.arange(window.y0, window.y1))
    _assert_ramp(preview_on, preview_off, 4 * np.arange(120) + 1.5)


def test_an_imperfection_from_a_test_module_reaches_the_batch_renderer(
    ramp: RowRamp, did_not_run: Callable[[str], None]
) -> None:
    if importlib.util.find_spec("mujoco_warp") is None:
        did_not_run("batch: mujoco_warp is not installed; the batch renderer's part did not run")
        return
    from headsim.sim.batch import BatchRenderer

    out = {}
    for grey in (0.0, RAMP_GREY):
        with HeadSim("default", _head(grey)) as sim:
            _pose(sim)
            out[grey] = BatchRenderer(sim, 1).render(sim.data.qpos[None, :].copy())[0, 0]
    _assert_ramp(out[RAMP_GREY], out[0.0], np.arange(480))


def test_an_imperfections_setting_is_a_scenario_key_with_its_range_and_meaning(
    ramp: RowRamp,
) -> None:
    scenario = load_scenario("quickstart", fast=True, overrides={"cam1.row_ramp_grey": RAMP_GREY})
    first, second = scenario.settings.cameras
    assert first.value(RAMP.name) == RAMP_GREY and second.value(RAMP.name) == 0.0
    record = settings_record(scenario.settings)["cameras"]
    assert record[0]["extra"] == ((RAMP.name, RAMP_GREY),) and "extra" not in record[1]
    with pytest.raises(ScenarioError) as refused:
        load_scenario("quickstart", fast=True, overrides={"cam2.row_ramp_grey": 101.0})
    message = str(refused.value)
    assert "cam2.row_ramp_grey" in message and "<= 100 grey levels" in message
    assert "\n" not in message
    keys = {key.path: key for key in accepted_keys()}
    for table in ("cam1", "cam2"):
        key = keys[f"{table}.{RAMP.name}"]
        assert key.description == RAMP.meaning
        assert key.allowed == "a number >= 0 and <= 100 grey levels" and key.default == "0"


def test_settings_outside_their_declared_range_are_refused_in_python(ramp: RowRamp) -> None:
    with pytest.raises(ValueError, match=r"row_ramp_grey must be within \[0, 100\] grey levels"):
        CameraSettings(**camera_values({RAMP.name: -1.0}))
    for extra in ((("noise_std", 1.0),), (("row_ramp_grey", 1.0),) * 2, (("unknown", 1.0),)):
        with pytest.raises(ValueError, match="registered imperfection settings other than"):
            CameraSettings(extra=extra)


def test_a_taken_name_is_refused() -> None:
    class Again(RowRamp):
        name = "noise"

    with pytest.raises(ValueError, match="'noise' is empty or taken"):
        imperfections.register(Again())


@pytest.mark.parametrize(
    "name", [s.name for s in imperfections.all_settings()], ids=lambda name: name
)
def test_every_registered_setting_moves_the_image_and_is_off_at_its_default(name: str) -> None:
    """Each declared setting at its example value changes the image; at its default the
    image is the ideal camera's.  (The figures each one moves are tested where it is
    measured: tests/sim/test_render.py's distortion shift and noise spread.)"""
    declared = imperfections.setting(name)
    assert declared.lo <= declared.default <= declared.hi and declared.meaning
    assert declared.lo <= declared.example <= declared.hi and declared.example != declared.default
    images = []
    for value in (declared.default, declared.example):
        camera = CameraSettings(**camera_values({name: value}))
        with HeadSim("default", HeadSettings(cameras=(camera, camera))) as sim:
            _pose(sim)
            images.append(sim.render(1).astype(float))
    with HeadSim("default") as ideal:
        _pose(ideal)
        np.testing.assert_array_equal(images[0], ideal.render(1))
    changed = float(np.mean(np.abs(images[1] - images[0]) > 2))
    print(f"{name} = {declared.example:g}: {changed:.1%} of the values changed by > 2 grey levels")
    assert changed > 0.01


def test_the_registry_applies_in_declared_order() -> None:
    order = [i.order for i in imperfections.registered()]
    assert order == sorted(order)
    names = [i.name for i in imperfections.registered()]
    assert names[:1] == ["distortion"]  # the lens resamples the canvas before pixel effects
