"""The measurement path never reads the truth: it reaches truth only through ``HeadSim.truth``
(for placing and scoring), shown by running scenarios on a simulator whose truth methods
raise when asked directly, whose settings show code outside the simulator only what
a head's specification gives (encoder resolution, image sizes, its model and belief), and
whose truth channel refuses the functions that measure (:data:`MEASURING`)."""

from __future__ import annotations

import inspect
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import pytest

from headsim.head.sim_head import SimHead
from headsim.runs import context
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario
from headsim.sim.simulator import HeadSim
from headsim.stereo.views import full_frame_board

#: HeadSim's truth methods: what is truly where (the ``Truth`` channel and its helpers).
TRUTH_METHODS = (
    "world_from_head",
    "world_from_camera",
    "head_from_camera",
    "frame_from_world",
    "position",
    "transform",
    "transform_points",
    "stereo_view",
    "stereo_views",
    "project",
    "camera_matrix",
    "dist_coeffs",
    "true_joint_angles",
    "effective_initial_direction",
)


class TruthRead(AssertionError):
    """A truth method called outside the truth channel."""


#: What a head's specification gives of its settings, and of each camera's.
SPECIFICATION = ("encoder_resolution_rad", "head", "believed", "seed", "joint_errors")
CAMERA_SPECIFICATION = ("width", "height", "image_centre")


class _Specification:
    """Only the named attributes of ``settings``; any other read raises."""

    def __init__(self, settings: Any, names: tuple[str, ...], what: str) -> None:
        self._settings, self._names, self._what = settings, names, what

    def __getattr__(self, name: str) -> Any:
        if name == "cameras" and self._what == "settings":
            return tuple(
                _Specification(camera, CAMERA_SPECIFICATION, "camera")
                for camera in self._settings.cameras
            )
        if name not in self._names:
            raise TruthRead(f"HeadSim {self._what}.{name} read outside the truth channel")
        return getattr(self._settings, name)


#: The functions that measure, by module (``"*"``: every function of the module): none may
#: ask a head or the simulator for the truth channel.  The live gaze, the servos it acquires
#: with, and the stereo baseline's corner, marker and triangulation steps.
MEASURING: dict[str, tuple[str, ...]] = {
    "headsim.live.gaze": ("*",),
    "headsim.live.estimator": ("*",),
    "headsim.active.neck_servo": ("*",),
    "headsim.active.look": ("*",),
    "headsim.active.markerless": ("*",),
    "headsim.stereo.views": ("board_view", "full_frame_board", "detect_chessboard"),
    "headsim.stereo.triangulation": (
        "detect_pair",
        "full_frame",
        "triangulate",
        "triangulate_cam1",
    ),
}


def _measuring_caller() -> str | None:
    """The measuring function (:data:`MEASURING`) that asked for the truth channel, if one
    did: the first of the package's frames up the stack outside the head's own code."""
    frame = inspect.currentframe()
    while frame is not None:
        module = frame.f_globals.get("__name__", "")
        if module.startswith("headsim.") and module != "headsim.head.sim_head":
            function = frame.f_code.co_name
            listed = MEASURING.get(module, ())
            return f"{module}.{function}" if "*" in listed or function in listed else None
        frame = frame.f_back
    return None


def _inside_simulator(depth: int = 2) -> bool:
    """Whether the caller ``depth`` frames up is the simulator's own code."""
    frame = inspect.currentframe()
    for _ in range(depth):
        assert frame is not None
        frame = frame.f_back
    return frame is not None and frame.f_globals.get("__name__") == "headsim.sim.simulator"


class GuardedSim(HeadSim):
    """A simulator whose truth methods raise unless called through :attr:`truth`, and whose
    settings show code outside it only the specification."""

    _open = 0

    @property
    def settings(self) -> Any:
        if self._open or _inside_simulator():
            return self._true_settings
        return _Specification(self._true_settings, SPECIFICATION, "settings")

    @settings.setter
    def settings(self, value: Any) -> None:
        self._true_settings = value

    def camera_settings(self, camera: Any) -> Any:
        true = super().camera_settings(camera)
        if self._open or _inside_simulator():
            return true
        return _Specification(true, CAMERA_SPECIFICATION, "camera_settings")

    @contextmanager
    def _opened(self) -> Iterator[None]:
        self._open += 1
        try:
            yield
        finally:
            self._open -= 1

    @property
    def truth(self) -> Any:
        measuring = _measuring_caller()
        if measuring is not None:
            raise TruthRead(f"{measuring} asked for the truth channel")
        sim = self

        class _Channel:
            def __getattr__(self, name: str) -> Any:
                with sim._opened():
                    value = getattr(sim, name)
                if not callable(value):
                    return value

                def opened(*args: Any, **kwargs: Any) -> Any:
                    with sim._opened():
                        return value(*args, **kwargs)

                return opened

        return _Channel()


def _guard(name: str) -> Callable[..., Any]:
    original = getattr(HeadSim, name)

    def guarded(self: GuardedSim, *args: Any, **kwargs: Any) -> Any:
        if not self._open:
            raise TruthRead(f"HeadSim.{name} read outside the truth channel")
        return original(self, *args, **kwargs)

    return guarded


for _name in TRUTH_METHODS:
    setattr(GuardedSim, _name, _guard(_name))


@pytest.mark.render
@pytest.mark.parametrize(
    "name",
    [
        "quickstart",
        "relative_positioning",
        "stereo",
        "zoom_fixed_points",
        "natural_field",
        "pursuit",
        "pursuit_textured",
    ],
)
def test_a_run_reads_truth_only_through_the_channel(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    scenario = load_scenario(name, fast=True)
    plain = run_scenario(scenario)
    # every place a run builds a simulator: each loaded module that names HeadSim
    builders = [
        module
        for name, module in list(sys.modules.items())
        if name.startswith("headsim.")
        and name != "headsim.sim.simulator"
        and getattr(module, "HeadSim", None) is HeadSim
    ]
    assert context in builders
    for module in builders:
        monkeypatch.setattr(module, "HeadSim", GuardedSim)
    guarded = run_scenario(scenario)
    assert guarded.failures == plain.failures
    assert len(guarded.records) == len(plain.records)
    for a, b in zip(plain.records, guarded.records, strict=True):
        assert np.array_equal(a.measurement.estimate_head_m, b.measurement.estimate_head_m)
        assert np.array_equal(a.measurement.truth_head_m, b.measurement.truth_head_m)
    if plain.calibration is not None:
        assert guarded.calibration is not None
        assert plain.calibration.alpha_e_rad == guarded.calibration.alpha_e_rad
    assert all(np.isfinite(r.measurement.truth_head_m).all() for r in guarded.records)
    assert repr(guarded.experiment) == repr(plain.experiment)


@pytest.mark.render
def test_the_guard_catches_a_direct_read() -> None:
    with GuardedSim() as sim:
        with pytest.raises(TruthRead, match="position"):
            sim.position("marker_red")
        with pytest.raises(TruthRead, match=r"settings\.baseline_m"):
            _ = sim.settings.baseline_m
        with pytest.raises(TruthRead, match=r"camera\.kx"):
            _ = sim.settings.cameras[0].kx
        with pytest.raises(TruthRead, match=r"camera_settings\.k1"):
            _ = sim.camera_settings(1).k1
        assert sim.settings.cameras[0].width == 640
        assert sim.truth.settings.baseline_m == 0.15
        assert sim.truth.camera_settings(1).k1 == sim.truth.settings.cameras[0].k1


@pytest.mark.render
def test_the_guard_refuses_the_channel_to_a_function_that_measures() -> None:
    class Peeking(SimHead):
        """A head whose grab asks for the truth: charged to the function grabbing."""

        def render(self, camera: int) -> np.ndarray:
            _ = self.truth
            return super().render(camera)

    with GuardedSim("chessboard") as sim:
        with pytest.raises(TruthRead, match=r"stereo\.views\.full_frame_board asked"):
            full_frame_board(Peeking(sim), 1)
        corners = full_frame_board(SimHead(sim), 1)  # a plain head measures
        assert corners is None or corners.shape == (48, 2)
        assert SimHead(sim).truth.settings.baseline_m == 0.15  # placing and scoring may ask
