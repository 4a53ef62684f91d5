"""Every figure of the orchestrators, with matplotlib's Agg backend, written atomically.

The study (``headsim study``, :mod:`headsim.studies.study`) draws one PNG per experiment:

- the comparison: per group (a head), the Tables V/VI errors target by target
  (left) and the RMS error of every method in every condition (right), on a
  log scale so that 0.05 % and 50 % read on one axis;
- a sweep: the RMS error against the swept value, one panel per calibration
  mode ("kept": calibrated before the change; "redone": calibrated on the
  changed head), and for the depth sweep a second panel in mm.

Every method keeps one colour and marker in every figure (:data:`STYLE`).
A sweep draws a metric against each swept field (:func:`plot_metric`), the
error budget its bar chart (:func:`plot_budget`).  Callers import this module
only when they draw, so that matplotlib loads only then.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib

matplotlib.use("Agg")  # no display; must precede pyplot
import matplotlib.pyplot as plt
import numpy as np

from headsim.files import write_bytes_atomic
from headsim.studies.methods import METHOD_LABELS

if TYPE_CHECKING:
    from headsim.studies.catalogue import ExperimentResult

#: Colour and marker per method.
STYLE: dict[str, dict[str, Any]] = {
    "stereo": {"color": "black", "marker": "s"},
    "active_v_known": {"color": "tab:blue", "marker": "o"},
    "active_centre": {"color": "tab:orange", "marker": "v"},
    "active_extended": {"color": "tab:green", "marker": "^"},
    "active_fixed_point": {"color": "tab:purple", "marker": "D"},
    "active_refound": {"color": "tab:pink", "marker": "P"},
}
MODE_TITLES = {
    "kept": "calibrated before the change",
    "redone": "calibrated on the changed head",
}


def _save(fig: plt.Figure, path: str | Path) -> Path:
    path = Path(path)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    data = buffer.getvalue()
    write_bytes_atomic(path, data)
    return path


def _methods(result: ExperimentResult) -> list[str]:
    return [s.method for s in result.results[0].summaries] if result.results else []


def plot_experiment(result: ExperimentResult, path: str | Path) -> Path:
    """The experiment's figure as a PNG at ``path``."""
    if result.experiment.kind == "compare":
        return plot_compare(result, path)
    return plot_sweep(result, path)


def plot_compare(result: ExperimentResult, path: str | Path) -> Path:
    """Per group: Tables V/VI target by target, and RMS per condition (both % of depth, log)."""
    methods = _methods(result)
    groups = list(result.experiment.base)
    fig, axes = plt.subplots(
        len(groups),
        2,
        figsize=(15, 4.6 * len(groups)),
        squeeze=False,
        width_ratios=(1, 1.4),
        layout="constrained",
    )
    width = 0.8 / max(len(methods), 1)
    for row, group in enumerate(groups):
        runs = [r for r in result.results if r.condition.group == group]
        before = runs[0]
        ax = axes[row, 0]
        count = len(before.condition.targets_head)
        for k, method in enumerate(methods):
            values = [e.error_pct_depth for e in before.errors if e.method == method]
            x = np.arange(count) + (k - (len(methods) - 1) / 2) * width
            ax.bar(x, values, width, color=STYLE[method]["color"], label=METHOD_LABELS[method])
        ax.set_xticks(
            np.arange(count),
            [f"{1e3 * z:.0f} mm" for z in before.condition.targets_head[:, 2]],
        )
        ax.set_yscale("log")
        ax.set_xlabel("target (true depth z_h)")
        ax.set_ylabel("3-D error, % of depth")
        ax.set_title(f"{group}: Tables V/VI, {before.condition.label}")
        ax.grid(axis="y", which="both", alpha=0.3)

        ax = axes[row, 1]
        labels = [r.condition.label for r in runs]
        for k, method in enumerate(methods):
            summaries = [r.summary(method) for r in runs]
            x = np.arange(len(runs)) + (k - (len(methods) - 1) / 2) * width
            ax.bar(
                x,
                [s.rms_pct_depth for s in summaries],
                width,
                color=STYLE[method]["color"],
                label=METHOD_LABELS[method],
            )
            for xi, s in zip(x, summaries, strict=True):
                if s.failed:
                    ax.annotate(f"{s.failed} lost", (xi, s.rms_pct_depth), fontsize=6, rotation=90)
        reference = before.summary("stereo").rms_pct_depth if "stereo" in methods else None
        if reference is not None and np.isfinite(reference):
            ax.axhline(reference, color="black", linestyle=":", linewidth=1)
        ax.set_xticks(np.arange(len(runs)), labels, rotation=15)
        ax.set_yscale("log")
        ax.set_ylabel("RMS 3-D error, % of depth")
        ax.set_title(f"{group}: after a change, calibrations kept (dotted: stereo before)")
        ax.grid(axis="y", which="both", alpha=0.3)
    handles, names = axes[0, 1].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncols=3, fontsize=9)
    fig.suptitle(
        result.experiment.title + f" (preset {result.config.preset}, seed {result.config.seed})"
    )
    return _save(fig, path)


def plot_sweep(result: ExperimentResult, path: str | Path) -> Path:
    """RMS error against the swept value, a panel per calibration mode (depth: % and mm)."""
    exp = result.experiment
    methods = _methods(result)
    modes = list(dict.fromkeys(r.condition.calibration for r in result.results))
    panels: list[tuple[str, str, str]] = [
        (mode, "rms_pct_depth", "RMS 3-D error, % of depth") for mode in modes
    ]
    if exp.name == "depth":
        panels.append((modes[0], "rms_mm", "RMS 3-D error, mm"))
    fig, axes = plt.subplots(
        1,
        len(panels),
        figsize=(6.5 * len(panels), 4.8),
        squeeze=False,
        sharey=exp.name != "depth",
        layout="constrained",
    )
    for ax, (mode, key, ylabel) in zip(axes[0], panels, strict=True):
        runs = [r for r in result.results if r.condition.calibration == mode]
        x = np.array([r.condition.value for r in runs])
        for method in methods:
            y = np.array([getattr(r.summary(method), key) for r in runs])
            ax.plot(x, y, label=METHOD_LABELS[method], linewidth=1.5, **STYLE[method])
            failed = [r.summary(method).failed for r in runs]
            for xi, yi, f in zip(x, y, failed, strict=True):
                if f and np.isfinite(yi):
                    ax.annotate(f"{f} lost", (xi, yi), fontsize=7, color=STYLE[method]["color"])
        ax.set_yscale("log")
        if exp.log_x:
            ax.set_xscale("log")
        ax.set_xlabel(exp.parameter)
        ax.set_ylabel(ylabel)
        title = MODE_TITLES[mode] if exp.name != "depth" else f"calibrated once ({ylabel[15:]})"
        ax.set_title(title)
        ax.grid(which="both", alpha=0.3)
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncols=3, fontsize=9)
    fig.suptitle(
        f"{exp.title} (preset {result.config.preset}, seed {result.config.seed}, "
        f"{len(runs[0].condition.targets_head) if runs else 0} targets per point)"
    )
    return _save(fig, path)


def plot_metric(rows: list[dict[str, Any]], x: str, y: str, path: Path, title: str) -> Path | None:
    """Scatter of ``y`` against ``x`` with the mean per x value; None if x is not numeric."""
    points = [
        (row[x], row[y])
        for row in rows
        if isinstance(row.get(x), int | float) and isinstance(row.get(y), int | float)
    ]
    if len(points) < 2:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs, ys = np.array(points, dtype=float).T
    fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
    ax.scatter(xs, ys, s=18, alpha=0.6, label="jobs")
    unique = np.unique(xs)
    if len(unique) < len(xs):
        ax.plot(unique, [ys[xs == u].mean() for u in unique], "o-", color="C3", label="mean")
    ax.set_xlabel(x)
    ax.set_ylabel("3-D error RMS, % of depth" if y == "rms_error_pct_depth" else y)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    plt.close(fig)
    write_bytes_atomic(path, buffer.getvalue())
    return path


#: The budget chart's bars: a row's key and the legend's label.
BUDGET_BARS = (
    ("rms_3d_pct", "3-D RMS, measured"),
    ("rms_xz_pct", "x-z RMS, measured"),
    ("predicted_xz_pct", "x-z, eqs. 17/19"),
)


def plot_budget(
    rows: Sequence[dict[str, Any]],
    path: Path,
    bars: Sequence[tuple[str, str]] = BUDGET_BARS,
    title: str = "Realistic head: error budget (rendered, scenario realistic_field)",
) -> Path:
    """A horizontal bar chart of ``bars`` (default: measured 3-D, measured x-z and
    predicted x-z), per condition, written atomically to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 0.45 * len(rows) + 1.6))
    y = np.arange(len(rows))
    for k, (key, label) in enumerate(bars):
        values = [0.0 if math.isnan(r[key]) else r[key] for r in rows]
        ax.barh(y + (k - 1) * 0.27, values, height=0.27, label=label)
    ax.set_yticks(y, [str(r["condition"]).strip() for r in rows])
    ax.invert_yaxis()
    ax.set_xlabel("error RMS, % of depth (whole field, 0.3-1.5 m)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    write_bytes_atomic(path, buffer.getvalue())
    return path
