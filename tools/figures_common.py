"""What the documentation's figure generators share: runs of today's code and how to read them.

Every key of results.json that a generator reads goes through :func:`summary`,
:func:`effort` or :func:`bands`, so that a renamed key is changed in one place.
Runs that more than one block quotes are cached for the process
(:func:`payload`), so the whole check runs each one once.
"""

from __future__ import annotations

import functools
import importlib.util
import json
import math
import os
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
#: Set (to "1") by ``readme_figures.py --write`` for its processes: generators that draw a
#: figure file (a PNG the pages show) draw it only then, not when checking.
WRITE_ENV = "HEADSIM_FIGURES_WRITE"


def writing() -> bool:
    """Whether this run rewrites the blocks (and so the figure files beside them)."""
    return os.environ.get(WRITE_ENV) == "1"


def run_payload(
    scenario: str, *, fast: bool = False, seed: int | None = None, **overrides: Any
) -> dict[str, Any]:
    """results.json's document of one scenario run (no files written)."""
    from headsim.runs.runner import run_scenario
    from headsim.runs.serialise import results_payload
    from headsim.scenario.loading import load_scenario

    loaded = load_scenario(scenario, fast=fast, seed=seed, overrides=overrides or None)
    return results_payload(run_scenario(loaded))


@functools.cache
def _cached(scenario: str, fast: bool, seed: int | None, overrides: str) -> dict[str, Any]:
    return run_payload(scenario, fast=fast, seed=seed, **json.loads(overrides))


def payload(
    scenario: str, *, fast: bool = False, seed: int | None = None, **overrides: Any
) -> dict[str, Any]:
    """:func:`run_payload`, run once per process for the same arguments."""
    return _cached(scenario, fast, seed, json.dumps(overrides, sort_keys=True))


@functools.cache
def benchmark(name: str) -> ModuleType:
    """The script ``benchmarks/NAME.py`` as a module (its functions, not its ``main``)."""
    path = ROOT / "benchmarks" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"benchmarks_{name}", path)
    assert spec is not None and spec.loader is not None, path
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # registered first, as an import does (dataclasses need it)
    spec.loader.exec_module(module)
    return module


# --- results.json's keys: read here only ---------------------------------------------


def summary(payload: dict[str, Any]) -> dict[str, Any]:
    """The run's one summary entry (the knowledge the head measured with)."""
    (entry,) = payload["summary"].values()
    return entry


def effort(payload: dict[str, Any]) -> dict[str, Any]:
    """What a run drew, every image a render: ``renders`` in all, ``calibration_renders``,
    ``experiment_renders``, ``measurement_renders`` (the experiment's that its
    measurements count), by kind ``images`` (full frames), ``windows``, ``retakes`` and
    ``previews``, and ``frames``, its pixels in full frames."""
    counts = payload["render_counts"]
    overall = counts["overall"]
    return {
        "renders": overall["total"],
        "calibration_renders": counts["calibration"]["total"],
        "experiment_renders": counts["experiment"]["total"],
        "measurement_renders": counts["experiment"]["in_measurements"],
        "images": overall["images"],
        "windows": overall["windows"],
        "retakes": overall["retakes"],
        "previews": overall["previews"],
        "frames": payload["rendered_frames"]["total"],
    }


def acceptance(payload: dict[str, Any]) -> dict[str, Any]:
    """The scene's targets: ``listed``, random ``drawn`` (refused draws included),
    ``refused`` by reason, ``accepted``, and those ``outside_start_view``."""
    return payload["scenario"]["scene"]["acceptance"]


def calibration_errors(payload: dict[str, Any]) -> dict[str, Any]:
    """The extended calibration against the truth: ``baseline_mm`` (effective baseline),
    ``offsets_mm`` (line-of-sight offsets), ``directions_mrad`` (initial directions), each
    found minus true; ``*_std`` their stated standard errors; balls ``fixated`` of
    ``targets``.  Only the two counts when the fit had no lines of sight."""
    c = payload["calibration"]
    out: dict[str, Any] = {"fixated": c["fixated"], "targets": c["targets"]}
    los = c.get("lines_of_sight")
    if not los:
        return out
    std = los["std_errors"]
    out["baseline_mm"] = 1e3 * (los["effective_baseline_m"] - los["effective_baseline_truth_m"])
    out["baseline_std_mm"] = 1e3 * los["effective_baseline_std_m"]
    out["offsets_mm"] = [
        1e3 * (a - b) for a, b in zip(los["offset_m"], los["offset_truth_m"], strict=True)
    ]
    out["offsets_std_mm"] = [1e3 * v for v in std["offset_m"]]
    out["directions_mrad"] = [
        1e3 * (a - b) for a, b in zip(los["alpha_e_rad"], c["alpha_e_truth_rad"], strict=True)
    ]
    out["directions_std_mrad"] = [1e3 * v for v in std["alpha_e_rad"]]
    return out


def band_rms(entry: dict[str, Any]) -> list[float]:
    """A summary entry's 3-D error RMS per depth band, % of depth, nearest band first."""
    return [b["error_pct_of_depth_rms"] for b in entry["by_depth"]]


def bands(entry: dict[str, Any]) -> str:
    """A summary entry's RMS by depth band: 'BAND: X % (COUNT); ...'."""
    return "; ".join(
        f"{b['band']}: {pct(b['error_pct_of_depth_rms'])} ({b['count']})" for b in entry["by_depth"]
    )


# --- formatting ---------------------------------------------------------------------


def pct(value: float | None, digits: int = 3) -> str:
    """``value`` in % with ``digits`` decimals; '-' for none."""
    return "-" if value is None or math.isnan(value) else f"{value:.{digits}f} %"


def num(value: float | None, digits: int = 3) -> str:
    """``value`` with ``digits`` decimals; '-' for none or NaN."""
    return "-" if value is None or math.isnan(value) else f"{value:.{digits}f}"


def span(values: Iterable[float], digits: int = 2, sep: str = "-") -> str:
    """'LOW-HIGH' of ``values`` (one number when they agree to the digits)."""
    vs = sorted(values)
    lo, hi = f"{vs[0]:.{digits}f}", f"{vs[-1]:.{digits}f}"
    return lo if lo == hi else f"{lo}{sep}{hi}"


def table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """A markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


# --- figures over seeds -------------------------------------------------------------

#: The seeds every headline figure is given over: each seed draws its own calibration
#: balls and targets, so the spread shows the calibration draw as well as the noise.
SEEDS = tuple(range(5))


def median(values: Sequence[float]) -> float:
    """The median of ``values`` (the mean of the middle two for an even count)."""
    vs = sorted(values)
    mid = len(vs) // 2
    return vs[mid] if len(vs) % 2 else 0.5 * (vs[mid - 1] + vs[mid])


def spread_pct(values: Sequence[float | None], digits: int = 3) -> str:
    """'MEDIAN % (MIN-MAX)' of per-seed values in %; '-' when no seed has one."""
    vs = [v for v in values if v is not None and not math.isnan(v)]
    if not vs:
        return "-"
    return f"{pct(median(vs), digits)} ({span(vs, digits)})"


def seeds_label(seeds: Sequence[int] = SEEDS) -> str:
    """'seeds 0-4' (or the list when they are not consecutive)."""
    s = list(seeds)
    if s == list(range(s[0], s[-1] + 1)) and len(s) > 1:
        return f"seeds {s[0]}-{s[-1]}"
    return "seeds " + ", ".join(map(str, s))
