"""The measurement path never reads the truth: it reaches truth only through ``HeadSim.truth``
(for placing and scoring), shown by running scenarios on a simulator whose truth methods
raise when asked directly, and whose settings show code outside the simulator only what
a head's specification gives (encoder resolution, image sizes, its model and belief)."""

from __future__ import annotations

import inspect
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import pytest

from headsim.runs import context
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario
from headsim.sim.simulator import HeadSim

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
