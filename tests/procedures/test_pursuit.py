"""The live pursuit, typed: its figures and its frames."""

from __future__ import annotations

from collections.abc import Callable

from headsim.procedures.pursuit import PursuitResult
from headsim.run.outcomes import RunResult


def test_the_target_is_never_lost(fast_run: Callable[[str], RunResult]) -> None:
    result = fast_run("pursuit")
    assert result.ok, result.failures
    e = result.experiment
    assert isinstance(e, PursuitResult) and e.failures == ()
    assert e.figures is not None and e.per_frame is not None
    assert e.figures.frames == len(e.per_frame["time_s"]) >= 15  # 0.5 s at 30 Hz
    assert e.figures.losses == 0 and all(e.per_frame["found"])
    assert e.figures.position_rms_pct_of_depth < 1.0
