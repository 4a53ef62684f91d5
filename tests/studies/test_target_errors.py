"""Measuring targets with every method: stereo's floor, and what a zoom breaks."""

from __future__ import annotations

import numpy as np

from headsim.active.principal import zoomed
from headsim.studies.methods import StudyConfig
from headsim.studies.target_errors import measure_methods, summarise
from headsim.studies.targets import table_targets

CONFIG = StudyConfig.quick()


def test_stereo_baseline_error_at_a_known_depth_is_below_a_tenth_of_a_percent(
    calibrations,
) -> None:
    errors = measure_methods(calibrations.settings, calibrations, [[0.03, 0.01, 0.6]], ("stereo",))
    (e,) = errors
    # Per camera a binned preview and the window it places (look_once), not a full frame.
    assert e.ok and e.renders == 4
    np.testing.assert_allclose(e.truth_head_m, [0.03, 0.01, 0.6], atol=1e-12)
    assert e.error_pct_depth < 0.25


def test_a_zoom_breaks_stale_stereo_and_the_image_centre_but_not_the_fixed_point(
    calibrations,
) -> None:
    methods = ("stereo", "active_v_known", "active_fixed_point")
    targets = table_targets(3)
    before = measure_methods(calibrations.settings, calibrations, targets, methods)
    after = measure_methods(zoomed(calibrations.settings, 1.5), calibrations, targets, methods)
    s0 = {m: summarise(before, m) for m in methods}
    s1 = {m: summarise(after, m) for m in methods}
    assert all(s.ok == 3 for s in (*s0.values(), *s1.values()))
    assert s0["stereo"].rms_pct_depth < 0.25 and s0["active_v_known"].rms_pct_depth < 0.25
    assert s1["stereo"].rms_mm > 5 * s0["stereo"].rms_mm
    # The paper's off-centre principal points: the image centre's rays turn by mrads.
    assert s1["active_v_known"].rms_pct_depth > 3.0
    assert s1["active_fixed_point"].rms_mm < 1.5 * s0["active_fixed_point"].rms_mm
    assert s1["active_fixed_point"].rms_pct_depth < 0.1
