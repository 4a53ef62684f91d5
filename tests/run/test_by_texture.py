"""The by-texture table's counting, from records made by hand: every target counts in its
class, failed ones included, by cause; a class whose targets all failed says so."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from headsim.active.failure import Failure, FailureCause
from headsim.codec import encode
from headsim.runs.outcomes import FixationScore, MeasurementRecord, by_texture
from headsim.runs.summary import texture_text
from headsim.runs.texture_class import TEXTURE_CLASSES

from .helpers import measurement

LOW = Failure(FailureCause.LOW_TEXTURE, "camera 2", 2, "flat patch")
AMBIGUOUS = Failure(FailureCause.AMBIGUOUS, "camera 2", 2, "two peaks")


def _score(vergence_deg: float, false: bool = False) -> FixationScore:
    return FixationScore(
        vergence_error_deg=vergence_deg,
        error_deg=(0.0, 0.0),
        error_m=(0.0, 0.0),
        landed=("a", "a"),
        landed_world_m=(None, None),
        click_error_px=0.0,
        image_error_px=(0.0, 0.0),
        match_sigma_px=0.02,
        match_score=0.9,
        match_ambiguity=0.1,
        match_status="ok",
        false_fixation=false,
        false_fixation_limit_m=0.005,
    )


def _record(
    name: str, error_m: float, failure: Failure | None = None, **score
) -> MeasurementRecord:
    m = replace(measurement(error_m, 0.5, failure), name=name)
    fixation = _score(math.nan) if failure is not None else _score(**score)
    return MeasurementRecord(m, "calibrated", 0, fixation=fixation)


def test_each_class_counts_its_targets_failed_ones_by_cause() -> None:
    records = [
        _record("a", 0.001, vergence_deg=0.01),
        _record("b", 0.002, vergence_deg=0.03, false=True),
        _record("c", 0.0, LOW),
        _record("d", 0.0, LOW),
        _record("e", 0.0, AMBIGUOUS),
        _record("f", 0.0005, vergence_deg=0.02),
    ]
    classes = {
        "a": "rich",
        "b": "rich",
        "c": "low",
        "d": "low",
        "e": "repetitive",
        "f": "repetitive",
    }
    rich, low, repetitive, occluded = by_texture(records, classes, TEXTURE_CLASSES)
    assert (rich.asked, rich.measured, rich.false_fixations) == (2, 2, 1)
    assert rich.error_pct_of_depth_rms == pytest.approx(math.sqrt((0.2**2 + 0.4**2) / 2))
    assert rich.vergence_error_deg_median == pytest.approx(0.02)
    assert rich.vergence_error_deg_rms == pytest.approx(math.sqrt((0.01**2 + 0.03**2) / 2))
    assert (low.asked, low.measured, low.failure_causes) == (2, 0, {"low texture": 2})
    assert math.isnan(low.error_pct_of_depth_rms)
    assert (repetitive.asked, repetitive.measured) == (2, 1)
    assert repetitive.failure_causes == {"ambiguous": 1}
    assert (occluded.asked, occluded.measured) == (0, 0)
    assert sum(c.asked for c in (rich, low, repetitive, occluded)) == len(records)
    assert rich.renders_per_point == 7.0
    assert (
        texture_text(low)
        == "low: 0 of 2 measured; failures by cause: 2 low texture; 7.0 renders per point"
    )
    assert texture_text(occluded) == "occluded: no targets"
    assert texture_text(repetitive).startswith(
        "repetitive: 1 of 2 measured, 3-D RMS 0.100 % of depth"
    )
    entry = encode(repetitive)
    assert entry["failure_causes"] == {"ambiguous": 1} and entry["asked"] == 2


def test_a_record_of_a_target_without_a_class_counts_in_none() -> None:
    records = [_record("a", 0.001, vergence_deg=0.01), _record("z", 0.001, vergence_deg=0.01)]
    table = by_texture(records, {"a": "low"}, TEXTURE_CLASSES)
    assert [c.asked for c in table] == [0, 1, 0, 0]
