"""The servos and the quick start's procedures reach the head through
:class:`~headsim.head.servo_head.ServoHead` alone: no module of theirs imports the
simulator, and the quick start runs the same on a :class:`SimHead` whose simulator is
sealed (reachable only from SimHead's own code) over a simulator whose truth opens only
through the truth channel."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import headsim
from headsim.head.interface import Head
from headsim.head.servo_head import ServoHead
from headsim.head.sim_head import SimHead
from headsim.runs import context
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario

from .test_truth_channel import GuardedSim

SIMULATOR = "headsim.sim.simulator"
PACKAGE = Path(headsim.__file__).resolve().parent

#: The modules of the servos, the live head, the stereo baseline and the procedures that
#: still import the simulator, and why.
#: The quick start's (Model 2, Model 1, fixation, the calibration procedure, every servo),
#: the chessboard's, relative positioning's, tracking's, zoom_fixed_points', pursuit's and
#: the stereo baseline's are not among them.
STILL_IMPORTING = {
    # PhaseStarted carries the simulator to the recording: the truth channel, for drawing.
    "headsim.active.events",
    # sample_board_pose and place_chessboard place the board (the simulator's job); the
    # corners are measured on the head (board_view).
    "headsim.stereo.views",
}


def _imports(path: Path) -> set[str]:
    """Every module ``path`` imports, at any depth (in functions, under TYPE_CHECKING)."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return found


@pytest.mark.fast
def test_only_the_listed_measuring_and_procedure_modules_import_the_simulator() -> None:
    importing = {
        f"headsim.{package}.{path.stem}"
        for package in ("active", "live", "stereo", "procedures")
        for path in sorted((PACKAGE / package).glob("*.py"))
        if SIMULATOR in _imports(path)
    }
    assert importing == STILL_IMPORTING


class SealedSimHead(SimHead):
    """A SimHead whose simulator only SimHead's own methods may reach: a servo or procedure
    that takes ``head.sim`` fails."""

    def __init__(self, sim: Any, camera_infos: Any = None) -> None:
        super().__init__(sim, camera_infos)
        self.reads: dict[str, int] = {}

    def __getattribute__(self, name: str) -> Any:
        if name == "sim":
            caller = inspect.currentframe()
            assert caller is not None and caller.f_back is not None
            module = caller.f_back.f_globals.get("__name__")
            if module != "headsim.head.sim_head":
                raise AssertionError(f"{module} reached the simulator behind the head")
        elif not name.startswith("_") and name not in ("reads",):
            reads = object.__getattribute__(self, "reads")
            reads[name] = reads.get(name, 0) + 1
        return object.__getattribute__(self, name)


@pytest.mark.render
def test_the_quick_start_runs_through_the_servo_head_alone(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    scenario = load_scenario("quickstart", fast=True)
    plain = run_scenario(scenario)
    heads: list[SealedSimHead] = []

    def sealed(sim: Any) -> SealedSimHead:
        heads.append(SealedSimHead(sim))
        return heads[-1]

    monkeypatch.setattr(context, "HeadSim", GuardedSim)  # truth only through the channel
    monkeypatch.setattr(context, "SimHead", sealed)
    sealed_run = run_scenario(scenario)
    assert len(heads) == 2  # the calibration's head and Model 2's
    assert sealed_run.failures == plain.failures == ()
    assert len(sealed_run.records) == len(plain.records) == 3
    for a, b in zip(plain.records, sealed_run.records, strict=True):
        assert np.array_equal(a.measurement.estimate_head_m, b.measurement.estimate_head_m)
        assert a.measurement.renders == b.measurement.renders
    assert plain.calibration is not None and sealed_run.calibration is not None
    assert plain.calibration.alpha_e_rad == sealed_run.calibration.alpha_e_rad
    # The servos looked in windows and previews and moved by whole steps, all on the head.
    for head in heads:
        for member in ("render_window", "render_preview", "command_eye_steps", "settle"):
            assert head.reads.get(member, 0) > 0, member
        assert isinstance(head, ServoHead) and isinstance(head, Head)
    with pytest.raises(AssertionError, match="reached the simulator behind the head"):
        _ = heads[0].sim


@pytest.mark.render
@pytest.mark.parametrize(
    ("name", "heads_built"),
    # The calibration's head and the procedure's; zoom_fixed_points: the head and its twin;
    # pursuit (no calibration): the live head's; stereo: the board's head and the targets'.
    [
        ("tracking", 2),
        ("chessboard", 2),
        ("relative_positioning", 2),
        ("zoom_fixed_points", 2),
        ("pursuit", 1),
        ("pursuit_textured", 1),
        ("stereo", 2),
    ],
)
def test_the_staging_procedures_run_on_the_head_the_runner_builds(
    monkeypatch: pytest.MonkeyPatch, name: str, heads_built: int
) -> None:
    # They place their boards, blocks and moving targets through the truth channel and
    # measure on the sealed head (pursuit: the live head over it, stepping the physics
    # its truth channel holds): the same results as on the plain one.
    scenario = load_scenario(name, fast=True)
    plain = run_scenario(scenario)
    heads: list[SealedSimHead] = []

    def sealed(sim: Any) -> SealedSimHead:
        heads.append(SealedSimHead(sim))
        return heads[-1]

    monkeypatch.setattr(context, "HeadSim", GuardedSim)
    monkeypatch.setattr(context, "SimHead", sealed)
    sealed_run = run_scenario(scenario)
    assert len(heads) == heads_built
    assert sealed_run.failures == plain.failures == ()
    assert len(sealed_run.records) == len(plain.records)
    for a, b in zip(plain.records, sealed_run.records, strict=True):
        assert np.array_equal(a.measurement.estimate_head_m, b.measurement.estimate_head_m)
        assert a.measurement.renders == b.measurement.renders
    assert repr(sealed_run.experiment) == repr(plain.experiment)
    assert sealed_run.renders == plain.renders
    assert all(head.render_count > 0 for head in heads)
