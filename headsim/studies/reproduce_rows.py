"""The comparison rows of ``headsim reproduce``'s report: per experiment, each quantity,
the paper's value, ours and the verdict."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from headsim.studies.catalogue import STUDY_JOB
from headsim.studies.checks import (
    CLOSE_TO_STEREO,
    INSENSITIVE,
    PAPER_ALPHA_E,
    PAPER_SIDE_MEAN_MM,
    PAPER_SIDE_STD_MM,
    SIDE_MEAN_TOLERANCE_MM,
    SIDE_STD_RATIO,
)


@dataclass(frozen=True)
class Row:
    """One line of a comparison table: a quantity, the paper's value, ours, the verdict."""

    quantity: str
    paper: str
    ours: str
    verdict: str


def _fmt(value: Any, spec: str = ".4f", unit: str = "") -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value:{spec}}{unit}"


def initial_direction_rows(calibration: dict[str, Any], check: dict[str, Any] | None) -> list[Row]:
    rows = []
    block = calibration["block"]
    for index in (0, 1):
        ours, std = block["alpha_e_rad"][index], block["alpha_e_std_rad"][index]
        paper = PAPER_ALPHA_E[index]
        agree = abs(ours - paper) <= max(3 * std, 5e-4)
        rows.append(
            Row(
                f"alpha_e{index + 1}, rad (head's true value = paper's)",
                f"{paper:+.4f}",
                f"{ours:+.5f} +- {std:.1e}",
                "reproduced" if agree else f"differs by {ours - paper:+.1e} rad",
            )
        )
    if check is not None:
        for target in check["results"]["experiment"].get("check_targets", []):
            before, after = target["error_m_uncalibrated"], target["error_m_calibrated"]
            better = after is not None and (before is None or after < before)
            rows.append(
                Row(
                    f"check target {target['name']}: error before -> after, mm",
                    "smaller after calibration",
                    f"{_fmt(None if before is None else 1e3 * before, '.2f')} -> "
                    f"{_fmt(None if after is None else 1e3 * after, '.2f')}",
                    "reproduced" if better else "not reproduced",
                )
            )
    return rows


def _side_mm(data: dict[str, Any] | None, key: str) -> float | None:
    value = None if data is None else data["results"]["experiment"].get(key)
    return None if value is None else 1e3 * value


def _side_rows(label: str, data: dict[str, Any] | None) -> list[Row]:
    """The square side's mean and std of one head against the paper's, within the bounds."""
    mean_mm, std_mm = _side_mm(data, "side_mean_m"), _side_mm(data, "side_std_m")
    low, high = SIDE_STD_RATIO
    if mean_mm is None:
        mean_verdict = "not reproduced (no figure)"
    elif abs(mean_mm - PAPER_SIDE_MEAN_MM) <= SIDE_MEAN_TOLERANCE_MM:
        mean_verdict = f"reproduced (within {SIDE_MEAN_TOLERANCE_MM} mm of the paper's)"
    else:
        mean_verdict = f"not reproduced (more than {SIDE_MEAN_TOLERANCE_MM} mm off the paper's)"
    ratio = None if std_mm is None else std_mm / PAPER_SIDE_STD_MM
    if ratio is None:
        std_verdict = "not reproduced (no figure)"
    elif low <= ratio <= high:
        std_verdict = f"reproduced (ratio within [{low}, {high}])"
    else:
        std_verdict = f"not reproduced (ratio outside [{low}, {high}])"
    return [
        Row(
            f"square side, mean, mm (true 30), {label}",
            f"{PAPER_SIDE_MEAN_MM}",
            _fmt(mean_mm, ".3f"),
            mean_verdict,
        ),
        Row(
            f"square side, std, mm, {label}",
            f"{PAPER_SIDE_STD_MM}",
            f"{_fmt(std_mm, '.3f')} (ours / paper's: {_fmt(ratio, '.3f')})",
            std_verdict,
        ),
    ]


def chessboard_rows(data: dict[str, Any]) -> list[Row]:
    """The paper preset's board (head.json), beside it the realistic preset's
    (``data["realistic"]``, absent when its job did not run)."""
    e = data["results"]["experiment"]
    realistic = data.get("realistic")
    return [
        *_side_rows("paper preset (ideal mechanics)", data),
        *_side_rows("realistic preset (real tolerances)", realistic),
        Row(
            "corners measured",
            "all",
            f"{e.get('corners_measured')} of {e.get('corners')}",
            "reproduced" if e.get("corners_measured") == e.get("corners") else "not reproduced",
        ),
    ]


def relative_rows(data: dict[str, Any]) -> list[Row]:
    e = data["results"]["experiment"]
    objects = len(e.get("objects", []))
    return [
        Row(
            "objects placed in the right area",
            "6 of 6",
            f"{e.get('agree')} of {objects}",
            "reproduced" if e.get("agree") == objects and objects else "not reproduced",
        ),
        Row(
            "alpha1, alpha2 at the cross point, rad",
            "0.0800, 0.0349",
            f"{_fmt(e.get('alpha1_rad'))}, {_fmt(e.get('alpha2_rad'))}",
            "reproduced (the scene stands the board where the paper's did)"
            if abs(e.get("alpha1_rad", math.nan) - 0.08) < 2e-3
            and abs(e.get("alpha2_rad", math.nan) - 0.0349) < 2e-3
            else "not comparable (depends on where the board stands)",
        ),
    ]


def tracking_rows(data: dict[str, Any]) -> list[Row]:
    summary = data["results"].get("summary", {})
    records = data["results"].get("measurements", [])
    errors = [1e3 * m["error_m"] for m in records if m.get("error_m") is not None]
    ok = sum(1 for m in records if m.get("status") == "ok")
    return [
        Row(
            "fixations measured",
            "(no tracking figure in the paper)",
            f"{ok} of {len(records)}",
            "ok" if ok == len(records) and records else "failures",
        ),
        Row(
            "3-D error, max, mm",
            "-",
            _fmt(max(errors) if errors else None, ".2f"),
            "-" if summary is None else "measured",
        ),
    ]


def study_rows(data: dict[str, Any]) -> list[Row]:
    figures = data.get("figures") or {}
    tables = figures.get("tables_v_vi", {})
    rows = [
        Row(
            "stereo (Zhang, distortion modelled), RMS 3-D error, mm",
            "Table V (values in the paper's table image)",
            _fmt(tables.get("stereo_rms_mm"), ".2f"),
            "reference",
        )
    ]
    labels = {
        "active_v_known_over_stereo": "active, v0 known (Table V) / stereo",
        "active_centre_over_stereo": "active, image centre (Table VI) / stereo",
        "active_extended_over_stereo": "active, extended calibration / stereo",
    }
    for key, label in labels.items():
        if key in tables:
            ratio = tables[key]
            rows.append(
                Row(
                    f"{label}, RMS ratio",
                    "'very close to stereovision'",
                    _fmt(ratio, ".2f"),
                    "reproduced" if ratio <= CLOSE_TO_STEREO else "not reproduced",
                )
            )
    zoom = figures.get("zoom_1_5_paper", {})
    for key, ratio in zoom.items():
        method = key.removesuffix("_after_over_before")
        insensitive = ratio <= INSENSITIVE
        paper = "degrades" if method == "stereo" else "'insensitive to intrinsic parameters'"
        if method == "stereo":
            verdict = (
                "reproduced (stereo degrades)" if not insensitive else "stereo did not degrade"
            )
        else:
            verdict = "reproduced" if insensitive else "not reproduced"
        rows.append(
            Row(
                f"focal length x1.5 after calibration, {method}: RMS after/before",
                paper,
                _fmt(ratio, ".2f"),
                verdict,
            )
        )
    return rows


ROWS: dict[str, Callable[[dict[str, Any]], list[Row]]] = {
    "chessboard": chessboard_rows,
    "relative_positioning": relative_rows,
    "tracking": tracking_rows,
    STUDY_JOB: study_rows,
}
