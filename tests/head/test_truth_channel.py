"""The measurement path never reads the truth: it reaches truth only through ``HeadSim.truth``
(for placing and scoring), shown by running the quick start on a simulator whose truth
methods raise when asked directly."""

from __future__ import annotations

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


class GuardedSim(HeadSim):
    """A simulator whose truth methods raise unless called through :attr:`truth`."""

    _open = 0

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
                method = getattr(sim, name)

                def opened(*args: Any, **kwargs: Any) -> Any:
                    with sim._opened():
                        return method(*args, **kwargs)

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
@pytest.mark.parametrize("name", ["quickstart", "relative_positioning"])
def test_a_run_reads_truth_only_through_the_channel(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    scenario = load_scenario(name, fast=True)
    plain = run_scenario(scenario)
    monkeypatch.setattr(context, "HeadSim", GuardedSim)
    guarded = run_scenario(scenario)
    assert guarded.ok and len(guarded.records) == len(plain.records) > 0
    for a, b in zip(plain.records, guarded.records, strict=True):
        assert np.array_equal(a.measurement.estimate_head_m, b.measurement.estimate_head_m)
        assert np.array_equal(a.measurement.truth_head_m, b.measurement.truth_head_m)
    if plain.calibration is not None:
        assert guarded.calibration is not None
        assert plain.calibration.alpha_e_rad == guarded.calibration.alpha_e_rad
    assert all(np.isfinite(r.measurement.truth_head_m).all() for r in guarded.records)


@pytest.mark.fast
def test_the_guard_catches_a_direct_read() -> None:
    with GuardedSim() as sim, pytest.raises(TruthRead, match="position"):
        sim.position("marker_red")
