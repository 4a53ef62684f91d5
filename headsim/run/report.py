"""What a run hands back: ``results.json`` for scripts and a summary table for people.

``results.json`` (README "Scenarios and results" documents every key) holds
no wall time and no timestamp: the same scenario, seed and software give the
same bytes.  Wall times go to ``timing.json`` and the printed summary.
SI units in the JSON (m, rad, px); the summary formats for people (mm, %).
"""

from __future__ import annotations

import math
import platform
from dataclasses import asdict
from importlib import metadata
from typing import Any

import cv2
import mujoco
import numpy as np
import scipy

import headsim
from headsim.run.runner import PAPER, MeasurementRecord, RunResult

#: Version of the results.json layout; bumped when a key changes meaning or goes.
RESULTS_SCHEMA = "headsim.results/1"

#: Keys of results.json and of each measurement in it (README documents each).
RESULTS_KEYS = (
    "schema",
    "scenario",
    "seed",
    "status",
    "failures",
    "software",
    "settings",
    "belief",
    "renders",
    "rendered_frames",
    "windows",
    "calibration",
    "measurements",
    "summary",
    "experiment",
)
MEASUREMENT_KEYS = (
    "name",
    "method",
    "status",
    "failure",
    "knowledge",
    "step",
    "time_s",
    "estimate_head_m",
    "truth_head_m",
    "estimate_world_m",
    "truth_world_m",
    "error_head_m",
    "error_m",
    "depth_m",
    "error_pct_of_depth",
    "covariance_head_m2",
    "renders",
    "search_renders",
    "servo_residual_px",
    "details",
)


def software_versions() -> dict[str, str]:
    """Versions of what produced the numbers."""

    def version(package: str) -> str:
        try:
            return metadata.version(package)
        except metadata.PackageNotFoundError:
            return "not installed"

    return {
        "headsim": headsim.__version__,
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "opencv": cv2.__version__,
        "rerun-sdk": version("rerun-sdk"),
    }


def measurement_entry(record: MeasurementRecord) -> dict[str, Any]:
    """One measurement as results.json holds it (NaN becomes null)."""
    m = record.measurement
    return {
        "name": m.name,
        "method": m.method,
        "status": m.status,
        "failure": None if m.failure is None else m.failure.as_dict(),
        "knowledge": record.knowledge,
        "step": record.step,
        "time_s": record.time_s,
        "estimate_head_m": m.estimate_head_m,
        "truth_head_m": m.truth_head_m,
        "estimate_world_m": m.estimate_world_m,
        "truth_world_m": m.truth_world_m,
        "error_head_m": m.error_head_m,
        "error_m": float(np.linalg.norm(m.error_head_m)),
        "depth_m": m.depth_m,
        "error_pct_of_depth": m.error_pct_of_depth,
        "covariance_head_m2": m.covariance_head_m2,
        "renders": m.renders,
        "search_renders": m.search_renders,
        "servo_residual_px": list(m.servo_residual_px),
        "details": dict(m.details),
    }


#: Depth bands of the honest headline, m: every target counts in exactly one.
DEPTH_BANDS_M = ((0.0, 0.6), (0.6, 1.0), (1.0, math.inf))


def _band_name(lo: float, hi: float) -> str:
    return f"{lo:g}-{hi:g} m" if math.isfinite(hi) else f">= {lo:g} m"


def _rms_pct(pct: np.ndarray) -> float:
    return float(np.sqrt(np.mean(pct * pct))) if pct.size else float("nan")


def _summary(records: list[MeasurementRecord]) -> dict[str, Any]:
    ok = [r.measurement for r in records if r.measurement.ok]
    errors = np.array([np.linalg.norm(m.error_head_m) for m in ok])
    pct = np.array([m.error_pct_of_depth for m in ok])
    residuals = [
        abs(x) for r in records for x in r.measurement.servo_residual_px if math.isfinite(x)
    ]
    nan = float("nan")
    return {
        "count": len(records),
        "ok": len(ok),
        "failed": len(records) - len(ok),
        "error_m_mean": float(errors.mean()) if ok else nan,
        "error_m_max": float(errors.max()) if ok else nan,
        "error_pct_of_depth_mean": float(pct.mean()) if ok else nan,
        "error_pct_of_depth_max": float(pct.max()) if ok else nan,
        "renders_per_point": float(np.mean([r.measurement.renders for r in records]))
        if records
        else nan,
        "servo_residual_px_max": max(residuals) if residuals else nan,
        "searched": sum(r.measurement.search_renders > 0 for r in records),
        "search_renders": sum(r.measurement.search_renders for r in records),
        "failure_causes": _cause_counts([r.measurement.failure for r in records]),
        # The whole field, all targets: the RMS of the 3-D error in % of depth,
        # and by depth band (count and RMS), so that no subset stands alone.
        "error_pct_of_depth_rms": _rms_pct(pct),
        "by_depth": [
            {
                "band": _band_name(lo, hi),
                "count": int(np.sum(sel)),
                "error_pct_of_depth_rms": _rms_pct(pct[sel]),
            }
            for lo, hi in DEPTH_BANDS_M
            for sel in [np.array([lo <= m.depth_m < hi for m in ok], dtype=bool)]
        ],
    }


def _cause_counts(failures: list[Any]) -> dict[str, int]:
    """How many failures had each cause (FailureCause values), most common first."""
    counts: dict[str, int] = {}
    for f in failures:
        if f is not None:
            counts[f.cause.value] = counts.get(f.cause.value, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: -kv[1]))


def summaries(result: RunResult) -> dict[str, dict[str, Any]]:
    """Statistics of the measurements, by what the head knew ("none", "calibrated")."""
    labels = dict.fromkeys(r.knowledge for r in result.records)
    return {
        label: _summary([r for r in result.records if r.knowledge == label]) for label in labels
    }


def results_payload(result: RunResult) -> dict[str, Any]:
    """The results.json document (plain data; :func:`headsim.run.results.write_json_atomic` writes it)."""
    s = result.scenario
    return {
        "schema": RESULTS_SCHEMA,
        "scenario": {
            "name": s.name,
            "file": s.path.name,
            "description": s.description,
            "procedure": s.experiment.procedure,
            "fast": s.fast,
            "preset": s.preset,
            "scene": asdict(s.scene),
            "experiment": asdict(s.experiment),
        },
        "seed": s.seed,
        "status": "ok" if result.ok else "failed",
        "failures": list(result.failures),
        "software": software_versions(),
        "settings": {**asdict(s.settings), "settle_mode": s.settle_mode},
        # The truth above; what the head believes (and its estimators use) here.
        "belief": asdict(s.settings.believed),
        "renders": result.renders,
        "rendered_frames": result.rendered_frames,
        "windows": result.windows,
        "calibration": result.calibration,
        "measurements": [measurement_entry(r) for r in result.records],
        "summary": summaries(result),
        "experiment": result.experiment,
    }


# -- the summary table ------------------------------------------------------------


def _cell(value: Any, fmt: str = "") -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return "-" if not math.isfinite(value) else format(value, fmt)
    return str(value)


def format_table(headers: list[str], rows: list[list[str]], indent: str = "  ") -> list[str]:
    """Columns padded to their widest cell; the first column left, the others right."""
    widths = [max(len(str(c)) for c in column) for column in zip(headers, *rows, strict=True)]

    def line(cells: list[str]) -> str:
        parts = [
            str(c).ljust(w) if k == 0 else str(c).rjust(w)
            for k, (c, w) in enumerate(zip(cells, widths, strict=True))
        ]
        return (indent + "  ".join(parts)).rstrip()

    return [line(headers), *(line(r) for r in rows)]


def _mm(value_m: float | None, fmt: str = ".2f") -> str:
    return _cell(None if value_m is None else value_m * 1000.0, fmt)


def _calibration_lines(block: dict[str, Any], paper: bool) -> list[str]:
    lines = [
        f"Calibration of the initial directions (Sec. V): {block.get('fixated', 0)} of "
        f"{block['targets']} ball positions fixated, {block.get('renders', 0)} renders"
    ]
    missed = [p["status"] for p in block.get("positions", []) if p["failure"] is not None]
    if missed:
        counts: dict[str, int] = {}
        for status in missed:
            key = status.split(" (")[0]
            counts[key] = counts.get(key, 0) + 1
        lines.append("  not fixated: " + ", ".join(f"{n} {k}" for k, n in counts.items()))
    if block["status"] != "ok":
        return [*lines, f"  {block['status']}"]
    headers = ["", "ours", "+-", "truth", "error"] + (["paper"] if paper else [])
    rows = []
    for k in range(2):
        rows.append(
            [
                f"alpha_e{k + 1} (rad)",
                _cell(block["alpha_e_rad"][k], ".5f"),
                _cell(block["alpha_e_std_rad"][k], ".1e"),
                _cell(block["alpha_e_truth_rad"][k], ".5f"),
                _cell(block["alpha_e_error_rad"][k], "+.1e"),
                *([_cell(block["alpha_e_paper_rad"][k], ".4f")] if paper else []),
            ]
        )
    vertical = block.get("vertical_reference")
    if vertical:
        for k in range(2):
            rows.append(
                [
                    f"v{k + 1}0 (px, extended)",
                    _cell(vertical["v0_px"][k], ".2f"),
                    _cell(vertical["v0_std_px"][k], ".2f"),
                    _cell(vertical["v0_truth_px"][k], ".2f"),
                    _cell(vertical["v0_px"][k] - vertical["v0_truth_px"][k], "+.2f"),
                    *(["-"] if paper else []),
                ]
            )
        for k in range(2):
            rows.append(
                [
                    f"kx{k + 1}/ky{k + 1} (extended)",
                    _cell(vertical["kx_over_ky"][k], ".4f"),
                    _cell(vertical["kx_over_ky_std"][k], ".4f"),
                    _cell(vertical["kx_over_ky_truth"][k], ".4f"),
                    _cell(vertical["kx_over_ky"][k] - vertical["kx_over_ky_truth"][k], "+.4f"),
                    *(["-"] if paper else []),
                ]
            )
    los = block.get("lines_of_sight")
    if los:
        truth_e = block["alpha_e_truth_rad"]
        for k in range(2):
            rows.append(
                [
                    f"alpha_e{k + 1} (rad, extended)",
                    _cell(los["alpha_e_rad"][k], ".5f"),
                    _cell(los["std_errors"]["alpha_e_rad"][k], ".1e"),
                    _cell(truth_e[k], ".5f"),
                    _cell(los["alpha_e_rad"][k] - truth_e[k], "+.1e"),
                    *(["-"] if paper else []),
                ]
            )
        for k in range(2):
            rows.append(
                [
                    f"s{k + 1} (mm, extended)",
                    _cell(1e3 * los["offset_m"][k], ".3f"),
                    _cell(1e3 * los["std_errors"]["offset_m"][k], ".3f"),
                    _cell(1e3 * los["offset_truth_m"][k], ".3f"),
                    _cell(1e3 * (los["offset_m"][k] - los["offset_truth_m"][k]), "+.3f"),
                    *(["-"] if paper else []),
                ]
            )
        rows.append(
            [
                "D effective (mm)",
                _cell(1e3 * los["effective_baseline_m"], ".3f"),
                _cell(1e3 * los["effective_baseline_std_m"], ".3f"),
                _cell(1e3 * los["effective_baseline_truth_m"], ".3f"),
                _cell(
                    1e3 * (los["effective_baseline_m"] - los["effective_baseline_truth_m"]), "+.3f"
                ),
                *(["-"] if paper else []),
            ]
        )
    out = lines + format_table(headers, rows)
    if los and not los["separable"]:
        out.append(f"  line-of-sight offsets: {los['message']}")
    return out


def _measurement_lines(result: RunResult) -> list[str]:
    records = result.records
    if not records:
        return []
    tracking = any(r.time_s is not None for r in records)
    several = len({r.knowledge for r in records}) > 1
    headers = ["name", *(["t s"] if tracking else []), *(["head knew"] if several else [])]
    headers += ["status", "depth m", "error mm", "% depth", "renders", "residual px"]
    rows = []
    for r in records:
        m = r.measurement
        error = float(np.linalg.norm(m.error_head_m))
        residual = " ".join(_cell(x, ".2f") for x in m.servo_residual_px) or "-"
        rows.append(
            [
                m.name,
                *([_cell(r.time_s, ".2f")] if tracking else []),
                *([r.knowledge] if several else []),
                m.status,
                _cell(m.depth_m, ".3f"),
                _mm(error),
                _cell(m.error_pct_of_depth, ".3f"),
                str(m.renders),
                residual,
            ]
        )
    methods = ", ".join(sorted({r.measurement.method for r in records}))
    lines = [f"Measurements ({methods}; error = |estimate - truth| in H)"]
    lines += format_table(headers, rows)
    for label, s in summaries(result).items():
        lines.append(
            f"  head knew {label}: {s['ok']} of {s['count']} ok; error mean {_mm(s['error_m_mean'])} mm "
            f"({_cell(s['error_pct_of_depth_mean'], '.3f')} % of depth), max {_mm(s['error_m_max'])} mm; "
            f"{_cell(s['renders_per_point'], '.1f')} renders per point; servo residual "
            f"<= {_cell(s['servo_residual_px_max'], '.2f')} px"
        )
        if s["searched"]:
            lines.append(
                f"  head knew {label}: {s['searched']} targets searched for again, "
                f"{s['search_renders']} renders of search"
            )
        if s["failure_causes"]:
            causes = ", ".join(f"{n} {c}" for c, n in s["failure_causes"].items())
            lines.append(f"  head knew {label}: failures by cause: {causes}")
        bands = "; ".join(
            f"{b['band']}: {_cell(b['error_pct_of_depth_rms'], '.3f')} % ({b['count']})"
            for b in s["by_depth"]
        )
        lines.append(
            f"    whole field, all {s['ok']} targets: 3-D error RMS "
            f"{_cell(s['error_pct_of_depth_rms'], '.3f')} % of depth; by depth: {bands}"
        )
    return lines


def _chessboard_lines(e: dict[str, Any], paper: bool) -> list[str]:
    headers = ["", "n", "mean mm", "std mm", "truth mm"] + (
        ["paper mean", "paper std"] if paper else []
    )
    rows = []
    for label, key, true_key in (
        ("widths", "width", "true_widths_m"),
        ("heights", "height", "true_heights_m"),
        ("all sides", "side", None),
    ):
        values = e["widths_m"] if key == "width" else e["heights_m"]
        if key == "side":
            values = np.concatenate([e["widths_m"], e["heights_m"]])
            truth = np.concatenate([e["true_widths_m"], e["true_heights_m"]])
        else:
            truth = np.asarray(e[true_key])
        paper_cells = ["-", "-"]
        if key == "side":
            paper_cells = [
                _mm(e["paper"]["side_mean_m"], ".1f"),
                _mm(e["paper"]["side_std_m"], ".3f"),
            ]
        rows.append(
            [
                label,
                str(len(values)),
                _mm(e[f"{key}_mean_m"], ".3f"),
                _mm(e[f"{key}_std_m"], ".3f"),
                _mm(float(np.mean(truth)) if len(truth) else None, ".3f"),
                *(paper_cells if paper else []),
            ]
        )
    title = (
        f"Chessboard squares (Tables III, IV): {e['corners_measured']} of {e['corners']} cross "
        f"points measured, squares {e['square_m'] * 1000:g} mm"
    )
    return [title, *format_table(headers, rows)]


def _relative_lines(e: dict[str, Any], paper: bool) -> list[str]:
    headers = ["", "ours"] + (["paper"] if paper else [])
    rows = [
        [
            "alpha1 (rad)",
            _cell(e["alpha1_rad"], ".4f"),
            *([_cell(e["paper"]["alpha1_rad"], ".4f")] if paper else []),
        ],
        [
            "alpha2 (rad)",
            _cell(e["alpha2_rad"], ".4f"),
            *([_cell(e["paper"]["alpha2_rad"], ".4f")] if paper else []),
        ],
        ["objects", str(len(e["objects"])), *([str(e["paper"]["objects"])] if paper else [])],
    ]
    lines = [
        "Relative positioning (Sec. III, Table VII): fixations on the cross point",
        *format_table(headers, rows),
    ]
    obj_rows = [
        [
            o["name"],
            o["colour"],
            f"S{o['area']}" if o["area"] else "-",
            f"S{o['true_area']}" if o["true_area"] else "-",
            "yes" if o["agree"] else "NO",
            _cell(o["margin_px"], ".1f"),
        ]
        for o in e["objects"]
    ]
    lines += format_table(["object", "colour", "area", "true area", "agree", "margin px"], obj_rows)
    lines.append(
        f"  {e['agree']} of {len(e['objects'])} objects in their true areas"
        + (f"; not seen: {', '.join(e['missing'])}" if e["missing"] else "")
    )
    return lines


def _tracking_lines(e: dict[str, Any]) -> list[str]:
    errors = np.asarray(e["errors_world_m"], dtype=float)
    finite = errors[np.isfinite(errors)]
    return [
        f"Tracking with the neck (Model 1): {len(finite)} of {len(errors)} fixations; error in W "
        f"mean {_mm(float(finite.mean()) if finite.size else None)} mm, max "
        f"{_mm(float(finite.max()) if finite.size else None)} mm; renders {e['renders_first']} for the "
        f"first fixation, {_cell(e['renders_after_mean'], '.1f')} per fixation after"
    ]


def _check_lines(e: dict[str, Any]) -> list[str]:
    rows = [
        [c["name"], _mm(c["error_m_uncalibrated"]), _mm(c["error_m_calibrated"])]
        for c in e["check_targets"]
    ]
    return [
        "Check targets: error before and after the calibration",
        *format_table(["target", "uncalibrated mm", "calibrated mm"], rows),
    ]


def summary_text(result: RunResult) -> str:
    """The table printed at the end of a run (figures of the paper beside ours for its head)."""
    s = result.scenario
    paper = s.paper_cameras
    e = result.experiment
    lines = [
        f"{s.name}{' (fast variant)' if s.fast else ''}: {s.description}",
        f"head: {s.preset} preset; seed {s.seed}; procedure {s.experiment.procedure}; "
        f"{result.renders['total']} renders"
        + (
            f" ({result.rendered_frames['total']:.1f} full frames of pixels)"
            if result.rendered_frames
            else ""
        )
        + ("; the paper's figures beside ours" if paper else ""),
        "",
    ]
    if result.calibration is not None:
        lines += [*_calibration_lines(result.calibration, paper), ""]
    measurement = _measurement_lines(result)
    if measurement:
        lines += [*measurement, ""]
    procedure = e["procedure"]
    if procedure == "chessboard" and "corners" in e:
        lines += [*_chessboard_lines(e, paper), ""]
    elif procedure == "relative_positioning" and "objects" in e:
        lines += [*_relative_lines(e, paper), ""]
    elif procedure == "tracking" and "errors_world_m" in e:
        lines += [*_tracking_lines(e), ""]
    elif procedure == "calibration" and "check_targets" in e:
        lines += [*_check_lines(e), ""]
    elif procedure == "pursuit" and "frames" in e:
        from headsim.live.procedure import summary_lines

        lines += [*summary_lines(e), ""]
    if result.ok and procedure == "pursuit":
        lines.append(f"OK: {e.get('frames', 0)} frames, the target never lost")
    elif result.ok:
        count = len(result.records)
        lines.append(f"OK: {count} measurement{'' if count == 1 else 's'}, none failed")
    else:
        lines.append(f"FAILED: {len(result.failures)} problem(s)")
        lines += [f"  {f}" for f in result.failures]
    return "\n".join(lines)


__all__ = [
    "MEASUREMENT_KEYS",
    "PAPER",
    "RESULTS_KEYS",
    "RESULTS_SCHEMA",
    "format_table",
    "measurement_entry",
    "results_payload",
    "software_versions",
    "summaries",
    "summary_text",
]
