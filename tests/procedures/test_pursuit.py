"""The live pursuit, typed: its figures and its frames."""

from __future__ import annotations

from collections.abc import Callable

from headsim.codec import encode
from headsim.procedures.pursuit import PursuitResult
from headsim.runs.result import RunResult
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario


def test_the_target_is_never_lost(fast_run: Callable[[str], RunResult]) -> None:
    result = fast_run("pursuit")
    assert result.ok, result.failures
    e = result.experiment
    assert isinstance(e, PursuitResult) and e.failures == ()
    assert e.figures is not None and e.per_frame is not None
    assert e.figures.frames == len(e.per_frame["time_s"]) >= 15  # 0.5 s at 30 Hz
    assert e.figures.losses == 0 and all(e.per_frame["found"])
    assert e.figures.position_rms_pct_of_depth < 1.0


def test_a_jump_is_refixated_and_the_run_is_kept_for_studies() -> None:
    path = {
        "kind": "jump",
        "start_world_m": [0.0, 1.0, 0.21],
        "end_world_m": [0.05, 1.0, 0.23],
        "time_s": 0.1,
    }
    overrides = {"scene.pursuit.path": path, "scene.pursuit.duration_s": 0.6}
    result = run_scenario(load_scenario("pursuit", fast=True, overrides=overrides))
    e = result.experiment
    assert isinstance(e, PursuitResult) and e.figures is not None and e.run is not None
    assert encode(e)["pursuit"]["path_kind"] == "jump" and "run" not in encode(e)
    since_jump = e.run.time_to_fixation_s(1.0, since_s=0.1)
    assert 0.0 < since_jump < 0.5  # refixated within the run, after the jump
    assert e.figures.frames == len(e.run.records) and e.figures.losses == 0
