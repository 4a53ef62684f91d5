"""Writing a study experiment: CSV rows per condition and per target, the JSON, the PNG
and the results.json index; and its table on stdout."""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

import numpy as np

from headsim.codec import encode
from headsim.files import to_jsonable, write_csv_atomic, write_json_atomic
from headsim.sim.settings import HeadSettings
from headsim.studies.catalogue import ExperimentResult, compare_figures
from headsim.studies.conditions import Condition
from headsim.studies.methods import METHOD_LABELS
from headsim.studies.output import write_rows


def _condition_columns(result: ExperimentResult, c: Condition) -> dict[str, Any]:
    """The columns every row starts with: the experiment and the condition."""
    return {
        "experiment": result.experiment.name,
        "group": c.group,
        "condition": c.label,
        "value": float(c.value),
        "calibration": c.calibration,
    }


def summary_rows(result: ExperimentResult) -> list[dict[str, Any]]:
    """A row per condition and method."""
    return [
        {**_condition_columns(result, r.condition), **encode(s)}
        for r in result.results
        for s in r.summaries
    ]


def target_rows(result: ExperimentResult) -> list[dict[str, Any]]:
    """A row per condition, method and target."""
    rows = []
    for r in result.results:
        c = r.condition
        for e in r.errors:
            t, est, err = e.truth_head_m, e.estimate_head_m, e.error_m
            rows.append(
                {
                    **_condition_columns(result, c),
                    "method": e.method,
                    "target": e.index,
                    "status": e.status,
                    "renders": e.renders,
                    "true_x_m": float(t[0]),
                    "true_y_m": float(t[1]),
                    "true_z_m": float(t[2]),
                    "estimate_x_m": float(est[0]),
                    "estimate_y_m": float(est[1]),
                    "estimate_z_m": float(est[2]),
                    "error_x_mm": float(1e3 * err[0]),
                    "error_y_mm": float(1e3 * err[1]),
                    "error_z_mm": float(1e3 * err[2]),
                    "error_mm": float(1e3 * np.linalg.norm(err)),
                    "error_pct_depth": e.error_pct_depth,
                }
            )
    return rows


def experiment_record(result: ExperimentResult, files: dict[str, Path]) -> dict[str, Any]:
    """A written experiment as a campaign's row: its title, summary rows, the comparison's
    figures (None for a sweep), its files and seconds."""
    return {
        "title": result.experiment.title,
        "summary": summary_rows(result),
        "figures": compare_figures(result) if result.experiment.kind == "compare" else None,
        "files": {k: str(p) for k, p in files.items()},
        "seconds": result.seconds,
    }


def write_experiment(
    result: ExperimentResult, out_dir: str | Path, figure: bool = True
) -> dict[str, Path]:
    """Write ``<name>.csv``, ``<name>_targets.csv``, ``<name>.json``, ``<name>.png`` and update
    ``results.json``; ``figure`` False: not the PNG (its caller draws it with
    ``headsim.studies.plots.plot_experiment``, e.g. in a process that has matplotlib loaded)."""
    out = Path(out_dir)
    name = result.experiment.name
    summaries = summary_rows(result)
    payload: dict[str, Any] = {
        "experiment": name,
        "title": result.experiment.title,
        "parameter": result.experiment.parameter,
        "config": result.config,
        "seconds": result.seconds,
        "methods": METHOD_LABELS,
        "summary": summaries,
        "calibrations": [
            {"head": _head_description(c.settings), **c.report()} for c in result.calibrations
        ],
        "targets": target_rows(result),
    }
    if result.experiment.kind == "compare":
        payload["figures"] = compare_figures(result)
    draw = functools.partial(_draw, result) if figure else None
    written = write_rows(out, name, summaries, payload, draw)
    files = {
        "csv": written["csv"],
        "targets_csv": write_csv_atomic(out / f"{name}_targets.csv", payload["targets"]),
        "json": written["json"],
        "png": out / f"{name}.png",
    }
    index_path = out / "results.json"
    index: dict[str, Any] = {}
    if index_path.exists():
        try:
            index = json.loads(index_path.read_text())
        except json.JSONDecodeError:
            index = {}
    index.setdefault("experiments", {})[name] = {
        "title": result.experiment.title,
        "seconds": result.seconds,
        "files": {k: p.name for k, p in files.items()},
        **({"figures": payload["figures"]} if "figures" in payload else {}),
    }
    write_json_atomic(index_path, to_jsonable(index))
    return files


def _draw(result: ExperimentResult, png: Path) -> None:
    from headsim.studies import plots  # matplotlib loads only when figures are written

    plots.plot_experiment(result, png)


def _head_description(settings: HeadSettings) -> dict[str, Any]:
    return {
        "cameras": [
            {
                "kx": c.kx,
                "ky": c.ky,
                "principal": c.principal,
                "k1": c.k1,
                "mount_yaw_rad": c.mount_yaw_rad,
                "noise_std": c.noise_std,
            }
            for c in settings.cameras
        ],
        "encoder_resolution_rad": settings.encoder_resolution_rad,
    }


def print_result(result: ExperimentResult) -> None:
    """The RMS 3-D error (% of depth) of every method in every condition, as a table on stdout."""
    exp = result.experiment
    methods = [s.method for s in result.results[0].summaries] if result.results else []
    print(f"\n== {exp.name}: {exp.title} ({result.seconds:.0f} s)")
    print("RMS 3-D error, % of depth (failed targets in brackets)")
    header = f"{'group':34s} {'condition':28s} {'calib':6s} " + " ".join(
        f"{m.removeprefix('active_'):>12s}" for m in methods
    )
    print(header)
    for r in result.results:
        c = r.condition
        cells = []
        for s in r.summaries:
            cell = f"{s.rms_pct_depth:.4f}" + (f"[{s.failed}]" if s.failed else "")
            cells.append(f"{cell:>12s}")
        print(f"{c.group:34s} {c.label:28s} {c.calibration:6s} " + " ".join(cells))
    if exp.kind == "compare":
        print(json.dumps(to_jsonable(compare_figures(result)), indent=2))
