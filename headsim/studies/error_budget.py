"""The realistic head's error budget: each imperfection off in turn, each calibration extension on/off.

``headsim study --experiment budget --out DIR [--fast]`` runs the
``realistic_field`` scenario (the realistic preset, 60 balls on a 1 mm tape,
60 targets over the whole shared field |x/z| <= 0.15, |y/z| <= 0.1, 0.3-1.5 m)
through the real scenario runner once per condition: rendered images, the
servo, the Sec. V calibration and its extensions, Model 2.  Every condition
uses the same seed, so the same calibration layout and targets.

Beside each measured row stands the paper's first-order error analysis for the
same tolerances (eqs. 17 and 19: the depth and x errors caused by an error
``dD`` in the baseline and ``d alpha_i`` in the eye angles; eqs. 15/16 are
their one-angle forms).  The inputs of that prediction, per target:

- ``dD``: with the line-of-sight offsets fitted, the calibrated effective
  baseline's stated covariance (with the directions'); without, the bias
  ``D - s1 + s2 - D_believed`` of the true baseline and of the first-order
  line-of-sight offsets ``s_i = e_i cos t_i - n_i sin t_i`` (forward ``n``,
  sideways ``e``, ``t_i`` the goal column's angle off the optical axis).
  Sec. V's depth fit then absorbs part of that bias into the initial
  directions: the mean ``d alpha_i`` is the least-squares answer of eq. 17
  over the calibration's own balls.
- ``d alpha_i``: the calibrated initial directions' stated covariance,
  the count error (true angle uniform within the count: res^2 / 12) and
  backlash (+-b/2 by the approach direction: b^2 / 4), independent.

The analysis covers the yaw mechanism only: y (eqs. 20-21 need the image
rows), axis tilt, the vertical reference and image noise are not in it, so
the prediction is of the x-z error and is set beside the measured x-z error.

Output in DIR: ``error_budget.csv``, ``error_budget.md``, ``error_budget.json``
and ``error_budget.png`` (bar chart).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from headsim.files import write_text_atomic
from headsim.geometry.kinematics import world_to_head
from headsim.runs.accuracy import DEPTH_BANDS_M
from headsim.sim.settings import HeadSettings
from headsim.studies.output import write_rows

#: The scenario the budget runs: the realistic head over the whole shared field.
SCENARIO = "realistic_field"
#: Calibration targets in ``--fast`` (the scenario's fast variant keeps 4 measured targets).
FAST_CALIBRATION_TARGETS = 12

_NOMINAL = {"head.baseline_m": 0.150, "head.neck_d1_m": 0.12, "head.neck_a2_m": 0.09}
_FORWARD_OFF = {
    "cam1.nodal_offset_m": 0.0,
    "cam2.nodal_offset_m": 0.0,
}
_SIDE_OFF = {"cam1.side_offset_m": 0.0, "cam2.side_offset_m": 0.0}
_COUNT_OFF = {"head.count_error": False}
_BACKLASH_OFF = {"head.backlash_rad": 0.0}
_TILT_OFF = {"cam1.eye_axis_tilt_rad": 0.0, "cam2.eye_axis_tilt_rad": 0.0}
_TAPE_OFF = {"experiment.calibration.position_noise_m": 0.0}
_NOISE_OFF = {"cam1.noise_std": 0.0, "cam2.noise_std": 0.0}
_NO_LINES = {"experiment.calibration.lines_of_sight": False}
_SEC5_ONLY = {"experiment.calibration.extended": False}


@dataclass(frozen=True)
class BudgetCondition:
    """One row: a name, the group it belongs to, and the scenario fields it sets."""

    name: str
    group: str
    overrides: dict[str, Any] = field(default_factory=dict)


def _all(*parts: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for part in parts:
        out.update(part)
    return out


#: Every row of the full budget, in order (the first is the realistic head as it is).
CONDITIONS: tuple[BudgetCondition, ...] = (
    BudgetCondition("realistic, everything on", "reference"),
    BudgetCondition("forward (nodal) offsets off", "imperfection off", _FORWARD_OFF),
    BudgetCondition("side offsets off", "imperfection off", _SIDE_OFF),
    BudgetCondition("baseline and D-H error off", "imperfection off", _NOMINAL),
    BudgetCondition("count error off", "imperfection off", _COUNT_OFF),
    BudgetCondition("backlash off", "imperfection off", _BACKLASH_OFF),
    BudgetCondition("eye axis tilt off", "imperfection off", _TILT_OFF),
    BudgetCondition("tape-measure noise off", "imperfection off", _TAPE_OFF),
    BudgetCondition("image noise off", "imperfection off", _NOISE_OFF),
    BudgetCondition(
        "every imperfection off",
        "imperfection off",
        _all(
            _FORWARD_OFF,
            _SIDE_OFF,
            _NOMINAL,
            _COUNT_OFF,
            _BACKLASH_OFF,
            _TILT_OFF,
            _TAPE_OFF,
            _NOISE_OFF,
        ),
    ),
    BudgetCondition("line-of-sight offsets not fitted", "calibration", _NO_LINES),
    BudgetCondition(
        "not fitted, optical-centre offsets off",
        "calibration",
        _all(_NO_LINES, _FORWARD_OFF, _SIDE_OFF),
    ),
    BudgetCondition("Sec. V only (no v0, kx/ky, offsets)", "calibration", _SEC5_ONLY),
)
#: The rows of ``--fast``: enough to show the offsets' cost and what the extensions buy.
FAST_CONDITIONS = ("realistic, everything on",
                   "line-of-sight offsets not fitted",
                   "not fitted, optical-centre offsets off",
                   "Sec. V only (no v0, kx/ky, offsets)")  # fmt: skip


def _band_name(lo: float, hi: float) -> str:
    return f"{lo:g}-{hi:g} m" if math.isfinite(hi) else f">= {lo:g} m"


BAND_NAMES = tuple(_band_name(lo, hi) for lo, hi in DEPTH_BANDS_M)


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(values**2))) if values.size else float("nan")


def first_order_offsets(settings: HeadSettings) -> tuple[float, float]:
    """(s1, s2), m: how far each image-centre column's line of sight misses its yaw axis."""
    out = []
    for cam in settings.cameras:
        t = float(cam.pinhole().column_angle(cam.image_centre[0]))
        out.append(cam.side_offset_m * math.cos(t) - cam.nodal_offset_m * math.sin(t))
    return (out[0], out[1])


def _depth_gains(big_d: float, x: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, ...]:
    """tan(alpha_i) and eq. 17's gains c_i = sec^2(alpha_i) / (tan alpha_1 + tan alpha_2)."""
    t1, t2 = (x + big_d / 2) / z, (big_d / 2 - x) / z
    return t1, t2, (1 + t1**2) / (t1 + t2), (1 + t2**2) / (t1 + t2)


def _absorbed(
    settings: HeadSettings, calibration: dict[str, Any], error_d: float
) -> tuple[float, float]:
    """The initial-direction errors by which Sec. V's depth fit absorbs a baseline error, rad.

    The fit makes every ball's depth right as nearly as it can, so to first
    order (eq. 17 at each fixated ball) it solves min sum z^2 (dD/D - c1 da1 - c2 da2)^2.
    """
    layout = calibration.get("layout") or {}
    positions, outcomes = layout.get("positions_world_m", []), calibration.get("positions", [])
    if len(positions) != len(outcomes):
        return (0.0, 0.0)
    fixated = [p for p, o in zip(positions, outcomes, strict=True) if o.get("status") == "ok"]
    if len(fixated) < 2 or error_d == 0.0:
        return (0.0, 0.0)
    balls = world_to_head(np.asarray(fixated), 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)
    x, z = balls[:, 0], balls[:, 2]
    _, _, c1, c2 = _depth_gains(settings.baseline_m, x, z)
    design = z[:, None] * np.column_stack([c1, c2])
    delta = np.linalg.lstsq(design, z * error_d / settings.baseline_m, rcond=None)[0]
    return (float(delta[0]), float(delta[1]))


def predicted_xz_pct(
    settings: HeadSettings, truth_head_m: np.ndarray, calibration: dict[str, Any]
) -> float:
    """Eqs. 17 and 19 to first order: RMS over the targets of |(dx, dz)| / z, % of depth.

    ``truth_head_m``: (N, 3) targets in H; ``calibration``: the run's
    calibration block (its stated standard errors).  See the module docstring.
    """
    if len(truth_head_m) == 0:
        return float("nan")
    big_d = settings.baseline_m
    x, z = truth_head_m[:, 0], truth_head_m[:, 2]
    t1, _, c1, c2 = _depth_gains(big_d, x, z)
    sec1 = 1 + t1**2  # 1 / cos^2(alpha_1)
    lines = calibration.get("lines_of_sight")
    if lines is not None and lines.get("separable", False):
        # (dD, da1, da2) from the fit's (alpha_e1, alpha_e2, s1, s2): D_eff = D - s1 + s2.
        mix = np.array([[0.0, 0.0, -1.0, 1.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
        cov = mix @ np.asarray(lines["covariance"]) @ mix.T
        mean = np.zeros(3)
    else:
        s1, s2 = first_order_offsets(settings)
        believed = settings.believed
        used = believed.baseline_m - believed.side_offset_m[0] + believed.side_offset_m[1]
        cov = np.zeros((3, 3))
        cov[1:, 1:] = np.asarray(calibration["alpha_e_covariance_rad2"])
        error_d = used - (big_d - s1 + s2)
        mean = np.array([error_d, *_absorbed(settings, calibration, error_d)])
    reading = (settings.encoder_resolution_rad**2 / 12 if settings.count_error else 0.0) + (
        settings.backlash_rad**2 / 4
    )
    cov = cov + np.diag([0.0, reading, reading])  # each reading's own error, independent
    # dz/z = dD/D - c1 da1 - c2 da2 (eq. 17); dx/z = (dz/z) tan a1 - dD/(2z) + da1/cos^2 a1
    # (eq. 19): each a row vector over (dD, da1, da2), one row per target.
    g_z = np.column_stack([np.full_like(z, 1 / big_d), -c1, -c2])
    g_x = g_z * t1[:, None] + np.column_stack([-0.5 / z, sec1, np.zeros_like(z)])
    expected = 0.0
    for g in (g_z, g_x):
        expected = expected + (g @ mean) ** 2 + np.einsum("ni,ij,nj->n", g, cov, g)
    return float(100 * np.sqrt(np.mean(expected)))


def run_condition(
    condition: BudgetCondition, *, fast: bool, seed: int, scenario: str = SCENARIO
) -> dict[str, Any]:
    """Run the scenario with ``condition``'s fields set; one row of the budget."""
    from headsim.codec import encode
    from headsim.runs.runner import run_scenario
    from headsim.scenario.loading import load_scenario

    overrides = dict(condition.overrides)
    if fast:
        overrides["experiment.calibration.targets"] = FAST_CALIBRATION_TARGETS
    start = time.perf_counter()
    loaded = load_scenario(scenario, fast=fast, seed=seed, overrides=overrides)
    result = run_scenario(loaded)
    ok = [r.measurement for r in result.records if r.measurement.ok]
    truth = np.array([m.truth_head_m for m in ok]).reshape(-1, 3)
    error = np.array([m.error_head_m for m in ok]).reshape(-1, 3)
    depth = truth[:, 2]
    pct = 100 * np.linalg.norm(error, axis=1) / depth if ok else np.zeros(0)
    pct_xz = 100 * np.linalg.norm(error[:, [0, 2]], axis=1) / depth if ok else np.zeros(0)
    calibration = encode(result.calibration) if result.calibration else {}
    lines = calibration.get("lines_of_sight")
    row: dict[str, Any] = {
        "condition": condition.name,
        "group": condition.group,
        "fields": "; ".join(f"{k} = {v}" for k, v in condition.overrides.items()) or "-",
        "measured": len(ok),
        "targets": len(result.records),
        "calibration_fixated": calibration.get("fixated"),
        "rms_3d_pct": _rms(pct),
    }
    for (lo, hi), name in zip(DEPTH_BANDS_M, BAND_NAMES, strict=True):
        sel = (depth >= lo) & (depth < hi)
        row[f"rms_3d_pct {name}"] = _rms(pct[sel])
        row[f"count {name}"] = int(np.sum(sel))
    row["rms_xz_pct"] = _rms(pct_xz)
    row["predicted_xz_pct"] = (
        predicted_xz_pct(loaded.settings, truth, calibration)
        if calibration.get("alpha_e_covariance_rad2") is not None
        else float("nan")
    )
    row["effective_baseline_error_mm"] = (
        1e3 * (lines["effective_baseline_m"] - lines["effective_baseline_truth_m"])
        if lines is not None
        else float("nan")
    )
    row["failures"] = "; ".join(result.failures)
    row["seconds"] = time.perf_counter() - start
    return row


@dataclass(frozen=True)
class BudgetJob:
    """One condition as a job for :func:`headsim.studies.jobs.map_jobs`."""

    index: int
    id: str
    condition: BudgetCondition
    fast: bool
    seed: int


def run_job(job: BudgetJob, marker_dir: str | None = None) -> dict[str, Any]:
    """One job in a worker process; the record carries its row."""
    row = run_condition(job.condition, fast=job.fast, seed=job.seed)
    return {"id": job.id, "index": job.index, "status": "ok", "row": row}


def run_budget(
    *,
    fast: bool = False,
    seed: int = 0,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Callable[[str], None] = lambda _: None,
    conditions: Sequence[BudgetCondition] | None = None,
) -> list[dict[str, Any]]:
    """Every row of the budget (``--fast``: :data:`FAST_CONDITIONS` on the fast variant)."""
    if conditions is None:
        conditions = (
            [c for c in CONDITIONS if c.name in FAST_CONDITIONS] if fast else list(CONDITIONS)
        )
    progress(f"== budget: the realistic head's error budget ({len(conditions)} conditions)")
    jobs = [BudgetJob(k, f"{k}-{c.name}", c, fast, seed) for k, c in enumerate(conditions)]

    def report(record: dict[str, Any]) -> None:
        if record.get("status") == "ok":
            row = record["row"]
            progress(f"  {row['condition']}: {row['rms_3d_pct']:.3f} % of depth")

    from headsim.studies.jobs import map_jobs

    records = map_jobs(run_job, jobs, workers=workers, scheduler=scheduler, on_record=report)
    bad = [r for r in records if r.get("status") != "ok"]
    if bad:
        raise RuntimeError(f"budget condition {bad[0]['id']} failed: {bad[0].get('error')}")
    return [r["row"] for r in records]


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return "-" if math.isnan(value) else f"{value:.3f}"
    return str(value)


def markdown_table(rows: Sequence[dict[str, Any]], fast: bool) -> str:
    """The budget as a markdown table (3-D RMS whole field and by band; x-z beside eqs. 17/19)."""
    title = "Error budget of the realistic head (" + (
        "fast: 12 calibration balls, 4 targets)" if fast else "60 calibration balls, 60 targets)"
    )
    head = ["condition", "measured", "3-D RMS %", *(f"{b} %" for b in BAND_NAMES)]
    head += ["x-z RMS %", "eqs. 17/19 x-z %", "D_eff error mm"]
    lines = [f"### {title}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        bands = [f"{_cell(r[f'rms_3d_pct {b}'])} ({r[f'count {b}']})" for b in BAND_NAMES]
        cells = [r["condition"], f"{r['measured']}/{r['targets']}", _cell(r["rms_3d_pct"]), *bands]
        cells += [
            _cell(r["rms_xz_pct"]),
            _cell(r["predicted_xz_pct"]),
            _cell(r["effective_baseline_error_mm"]),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    lines += [
        "",
        "RMS of the error in % of the true depth over every measured target of the whole "
        "shared field (|x/z| <= 0.15, |y/z| <= 0.1, 0.3-1.5 m), and by depth band (count). "
        "eqs. 17/19: the paper's first-order analysis for the same tolerances (baseline, "
        "line-of-sight offsets, calibrated directions, count error, backlash); it has no y, "
        "tilt or image-noise term, so it stands beside the measured x-z error.",
    ]
    return "\n".join(lines) + "\n"


def _draw(rows: Sequence[dict[str, Any]], png: Path) -> None:
    from headsim.studies.plots import plot_budget  # matplotlib loads only for the chart

    plot_budget(rows, png)


def write_budget(
    rows: Sequence[dict[str, Any]], out_dir: str | Path, fast: bool
) -> dict[str, Path]:
    """Write error_budget.csv, .md, .json and .png to ``out_dir``; their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    md = write_text_atomic(out / "error_budget.md", markdown_table(rows, fast))
    document = {"scenario": SCENARIO, "fast": fast, "rows": list(rows)}
    written = write_rows(out, "error_budget", rows, document, functools.partial(_draw, rows))
    return {"csv": written["csv"], "md": md, "json": written["json"], "png": written["png"]}
