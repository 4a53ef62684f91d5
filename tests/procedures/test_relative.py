"""Relative positioning: the cross point, then each object's area (Sec. III, VI-C)."""

from __future__ import annotations

from collections.abc import Callable

from headsim.procedures.relative import RelativeResult
from headsim.runs.result import RunResult


def test_every_object_is_in_its_true_area(fast_run: Callable[[str], RunResult]) -> None:
    result = fast_run("relative_positioning")
    assert result.ok, result.failures
    e = result.experiment
    assert isinstance(e, RelativeResult)
    assert e.agree == len(e.objects) == 6 and e.missing == []
    assert len({o.area for o in e.objects}) == 6
    assert all(o.agree and o.area == o.true_area for o in e.objects)
    assert abs(e.alpha1_rad - e.paper.alpha1_rad) < 1e-3
