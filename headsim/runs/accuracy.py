"""Statistics of a run's measurements, by what the head knew: counts, errors, depth bands.

The honest headline: the RMS of the 3-D error in % of depth over the whole
field and all targets, and by depth band (every target counts in exactly one);
beside it, labelled, the edge of the field apart: the targets that the start
pose does not show whole to both cameras (``TargetAcceptance.outside_start_view``).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence

import numpy as np

from headsim.active.failure import Failure
from headsim.active.measurement import Measurement
from headsim.codec import declared, doc
from headsim.runs.outcomes import MeasurementRecord

#: Depth bands of the honest headline, m: every target counts in exactly one.
DEPTH_BANDS_M = ((0.0, 0.6), (0.6, 1.0), (1.0, math.inf))


@declared
class DepthBand:
    """One depth band: its name (e.g. "0.6-1 m"), the targets measured in it (``count``),
    every target whose true depth lies in it (``asked``, failed ones included) and the
    measured ones' RMS error, %."""

    band: str = doc("the band")
    count: int = doc("measurements in it")
    asked: int = doc("targets whose true depth lies in it, the failed ones included")
    error_pct_of_depth_rms: float = doc("their RMS error, % of depth")


@declared
class TargetGroup:
    """Some of the measurements, named apart: how many, how many ok, their RMS error, %."""

    count: int = doc("how many")
    ok: int = doc("how many succeeded")
    error_pct_of_depth_rms: float = doc("their RMS error, % of depth")


@declared
class MeasurementSummary:
    """The measurements made with one knowledge: counts, errors (m, % of depth), renders.

    NaN where undefined (no measurement succeeded).  ``failure_causes``: how
    many failures had each cause (FailureCause values), most common first.
    ``scanned``: measurements that scanned for a target the head's pose did not
    show, ``scan_renders`` their scans' renders (in ``search_renders``).
    ``outside_start_view``: the measurements of targets that the start pose does
    not show whole to both cameras (the edge of the field), apart.
    """

    count: int = doc("measurements")
    ok: int = doc("measurements that succeeded")
    failed: int = doc("measurements that failed")
    error_m_mean: float = doc("mean 3-D error, m")
    error_m_max: float = doc("largest 3-D error, m")
    error_pct_of_depth_mean: float = doc("mean error, % of depth")
    error_pct_of_depth_max: float = doc("largest error, % of depth")
    renders_per_point: float = doc("renders per measurement")
    servo_residual_px_max: float = doc("largest servo residual, px")
    searched: int = doc("measurements that needed a search")
    search_renders: int = doc("their search renders")
    failure_causes: dict[str, int] = doc("cause -> count")
    error_pct_of_depth_rms: float = doc("RMS error of all targets, % of depth")
    by_depth: tuple[DepthBand, ...] = doc("per depth band 0-0.6, 0.6-1, >= 1 m")
    scanned: int = doc(
        "measurements that scanned for a target the start pose did not show", default=0
    )
    scan_renders: int = doc("their scan renders", default=0)
    outside_start_view: TargetGroup = doc(
        "the targets the start pose did not show whole to both cameras (the field's edge, a labelled subset)",
        default=TargetGroup(0, 0, float("nan")),
    )


def _band_name(lo: float, hi: float) -> str:
    return f"{lo:g}-{hi:g} m" if math.isfinite(hi) else f">= {lo:g} m"


def _rms_pct(pct: np.ndarray) -> float:
    return float(np.sqrt(np.mean(pct * pct))) if pct.size else float("nan")


def summarise(
    records: Sequence[MeasurementRecord], outside_start_view: Collection[str] = ()
) -> MeasurementSummary:
    """The statistics of ``records``; ``outside_start_view``: the names of the targets at
    the edge of the field (not seen whole by both cameras at the start pose)."""
    ok = [r.measurement for r in records if r.measurement.ok]
    errors = np.array([np.linalg.norm(m.error_head_m) for m in ok])
    pct = np.array([m.error_pct_of_depth for m in ok])
    residuals = [
        abs(x) for r in records for x in r.measurement.servo_residual_px if math.isfinite(x)
    ]
    nan = float("nan")
    return MeasurementSummary(
        count=len(records),
        ok=len(ok),
        failed=len(records) - len(ok),
        error_m_mean=float(errors.mean()) if ok else nan,
        error_m_max=float(errors.max()) if ok else nan,
        error_pct_of_depth_mean=float(pct.mean()) if ok else nan,
        error_pct_of_depth_max=float(pct.max()) if ok else nan,
        renders_per_point=float(np.mean([r.measurement.renders for r in records]))
        if records
        else nan,
        servo_residual_px_max=max(residuals) if residuals else nan,
        searched=sum(r.measurement.search_renders > 0 for r in records),
        search_renders=sum(r.measurement.search_renders for r in records),
        failure_causes=_cause_counts([r.measurement.failure for r in records]),
        error_pct_of_depth_rms=_rms_pct(pct),
        by_depth=tuple(
            DepthBand(
                _band_name(lo, hi),
                int(np.sum(sel)),
                sum(lo <= r.measurement.depth_m < hi for r in records),
                _rms_pct(pct[sel]),
            )
            for lo, hi in DEPTH_BANDS_M
            for sel in [np.array([lo <= m.depth_m < hi for m in ok], dtype=bool)]
        ),
        scanned=sum(r.measurement.scan_renders > 0 for r in records),
        scan_renders=sum(r.measurement.scan_renders for r in records),
        outside_start_view=_group(
            [r.measurement for r in records if r.measurement.name in outside_start_view]
        ),
    )


def _group(ms: Sequence[Measurement]) -> TargetGroup:
    pct = np.array([m.error_pct_of_depth for m in ms if m.ok])
    return TargetGroup(len(ms), int(pct.size), _rms_pct(pct))


def _cause_counts(failures: Sequence[Failure | None]) -> dict[str, int]:
    """How many failures had each cause (FailureCause values), most common first."""
    counts: dict[str, int] = {}
    for f in failures:
        if f is not None:
            counts[f.cause.value] = counts.get(f.cause.value, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: -kv[1]))


def summaries(
    records: Sequence[MeasurementRecord], outside_start_view: Collection[str] = ()
) -> dict[str, MeasurementSummary]:
    """Statistics of the measurements, by what the head knew ("none", "calibrated");
    ``outside_start_view`` as :func:`summarise`'s."""
    labels = dict.fromkeys(r.knowledge for r in records)
    return {
        label: summarise([r for r in records if r.knowledge == label], outside_start_view)
        for label in labels
    }


__all__ = [
    "DEPTH_BANDS_M",
    "DepthBand",
    "MeasurementSummary",
    "TargetGroup",
    "summaries",
    "summarise",
]
