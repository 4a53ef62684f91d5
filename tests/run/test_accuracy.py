"""A run's statistics: counted by knowledge, errors over the whole field and by depth band."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.runs.accuracy import DEPTH_BANDS_M, summaries, summarise
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.summary import band_text

from .helpers import LOST, measurement


def test_summaries_count_by_knowledge_and_depth_band() -> None:
    records = [
        MeasurementRecord(measurement(0.001, 0.5), "none", 0),
        MeasurementRecord(measurement(0.004, 0.8), "calibrated", 1),
        MeasurementRecord(measurement(0.0, 1.2, LOST), "calibrated", 2),
    ]
    by_knowledge = summaries(records)
    assert list(by_knowledge) == ["none", "calibrated"]
    calibrated = by_knowledge["calibrated"]
    assert (calibrated.count, calibrated.ok, calibrated.failed) == (2, 1, 1)
    assert calibrated.failure_causes == {"lost": 1}
    assert [b.count for b in calibrated.by_depth] == [0, 1, 0]  # the failed one counts nowhere
    assert calibrated.error_pct_of_depth_rms == pytest.approx(0.5)


def test_every_depth_counts_in_exactly_one_band() -> None:
    depths = [0.3, 0.6, 0.99, 1.0, 2.5]
    records = [MeasurementRecord(measurement(0.001, d), "none", k) for k, d in enumerate(depths)]
    s = summarise(records)
    assert len(s.by_depth) == len(DEPTH_BANDS_M)
    assert [b.count for b in s.by_depth] == [1, 2, 2]
    assert [b.band for b in s.by_depth] == ["0-0.6 m", "0.6-1 m", ">= 1 m"]
    pct = np.array([0.1 / d for d in depths])
    assert s.error_pct_of_depth_rms == pytest.approx(float(np.sqrt(np.mean(pct**2))))
    assert s.servo_residual_px_max == 0.5 and s.renders_per_point == 7.0


def test_a_band_whose_targets_all_failed_says_so_and_is_not_called_empty() -> None:
    records = [
        MeasurementRecord(measurement(0.0, 0.5, LOST), "calibrated", 0),
        MeasurementRecord(measurement(0.0, 0.55, LOST), "calibrated", 1),
        MeasurementRecord(measurement(0.004, 0.8), "calibrated", 2),
        MeasurementRecord(measurement(0.0, 0.9, LOST), "calibrated", 3),
    ]
    near, middle, far = summarise(records).by_depth
    assert (near.count, near.asked) == (0, 2)
    assert (middle.count, middle.asked) == (1, 2)
    assert (far.count, far.asked) == (0, 0)
    assert band_text(near) == "0-0.6 m: 0 of 2 measured"
    assert band_text(middle) == "0.6-1 m: 0.500 % (1 of 2 measured)"
    assert band_text(far) == ">= 1 m: no targets"
