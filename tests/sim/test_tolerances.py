"""The realistic tolerance budget (sim/tolerances.py): units, sources, and the preset built to it."""

from __future__ import annotations

import pytest

from headsim.paper import BASELINE_M
from headsim.sim.settings import HeadSettings, realistic_head
from headsim.sim.tolerances import REALISTIC_BUDGET


def test_every_entry_has_a_positive_value_its_keys_unit_and_a_source() -> None:
    assert len(REALISTIC_BUDGET) == 8
    for key, (value, unit, source) in REALISTIC_BUDGET.items():
        assert value > 0, key
        suffix = key.rsplit("_", 1)[-1]
        assert unit == (suffix if suffix in ("m", "rad") else "count"), key
        assert len(source) > 40, key


def test_the_realistic_preset_is_the_paper_head_built_to_the_budget() -> None:
    b = {key: value for key, (value, _, _) in REALISTIC_BUDGET.items()}
    head = realistic_head()
    nominal = HeadSettings()
    assert head.baseline_m == pytest.approx(BASELINE_M + b["baseline_error_m"], abs=1e-15)
    assert head.neck_d1_m == pytest.approx(nominal.neck_d1_m + b["neck_error_m"], abs=1e-15)
    assert head.neck_a2_m == pytest.approx(nominal.neck_a2_m - b["neck_error_m"], abs=1e-15)
    assert head.backlash_rad == b["backlash_rad"] and head.count_error
    cam1, cam2 = head.cameras
    assert cam1.nodal_offset_m == cam2.nodal_offset_m == b["nodal_offset_m"]
    assert (cam1.side_offset_m, cam2.side_offset_m) == (
        b["side_offset_m"],
        -0.5 * b["side_offset_m"],
    )
    assert (cam1.eye_axis_tilt_rad, cam2.eye_axis_tilt_rad) == (
        b["eye_axis_tilt_rad"],
        -0.5 * b["eye_axis_tilt_rad"],
    )
    # The head believes the nominal design, not the errors it was built with.
    assert head.believed.baseline_m == pytest.approx(BASELINE_M)
