"""The documentation's figures of real scenes: markerless fixation in a textured room,
beside markers on the same points, by depth band and texture class, and the theory."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from figures_common import (
    ROOT,
    SEEDS,
    effort,
    num,
    payload,
    seeds_label,
    spread_pct,
    summary,
    table,
)

from headsim.estimators.errors import rel_dz_correspondence

#: natural_field's depth bands (the runner's), nearest first.
BANDS = ("0-0.6 m", "0.6-1 m", ">= 1 m")
#: The texture classes, in the order the tables give them.
TEXTURES = ("rich", "low", "repetitive", "occluded")


@functools.cache
def _runs(scenario: str) -> tuple[dict[str, Any], ...]:
    """``scenario`` (full) at each of :data:`SEEDS`."""
    return tuple(payload(scenario, seed=seed) for seed in SEEDS)


def _targets(runs: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Every markerless target asked for over the runs, each a measurement with its seed
    and its texture class."""
    out = []
    for seed, p in enumerate(runs):
        classes = {
            t["name"]: t["texture_class"] for t in p["experiment"]["surface_targets"]["targets"]
        }
        out += [
            {**m, "seed": seed, "texture_class": classes[m["name"]]}
            for m in p["measurements"]
            if m.get("fixation") is not None
        ]
    return out


def _band(depth_m: float) -> str:
    return BANDS[0] if depth_m < 0.6 else BANDS[1] if depth_m < 1.0 else BANDS[2]


def _rms(values: Sequence[float]) -> float:
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else math.nan


def _cause(m: dict[str, Any]) -> str:
    return str(m["failure"]["cause"]) if m.get("failure") else "ok"


def _row(targets: Sequence[dict[str, Any]], renders_per_point: float | None) -> list[str]:
    """measured / asked; 3-D RMS %; by band; vergence median / RMS; false; failures."""
    ok = [m for m in targets if m["status"] == "ok"]
    pct = [m["error_pct_of_depth"] for m in ok]
    by_band = []
    for band in BANDS:
        asked = [m for m in targets if _band(m["depth_m"]) == band]
        measured = [m["error_pct_of_depth"] for m in asked if m["status"] == "ok"]
        cell = f"{num(_rms(measured))} ({len(measured)}/{len(asked)})" if asked else "-"
        by_band.append(cell)
    vergence = [
        m["fixation"]["vergence_error_deg"]
        for m in ok
        if m["fixation"]["vergence_error_deg"] is not None
    ]
    causes: dict[str, int] = {}
    for m in targets:
        if m["status"] != "ok":
            causes[_cause(m)] = causes.get(_cause(m), 0) + 1
    failures = ", ".join(f"{n} {c}" for c, n in sorted(causes.items(), key=lambda kv: -kv[1]))
    return [
        f"{len(ok)} / {len(targets)}",
        num(_rms(pct)),
        *by_band,
        f"{num(float(np.median(vergence)) if vergence else math.nan, 4)} / {num(_rms(vergence), 4)}",
        f"{sum(1 for m in ok if m['fixation']['false_fixation'])} of {len(ok)}; "
        f"{sum(1 for m in targets if m['fixation'].get('wrong_match'))}",
        failures or "none",
        "-" if renders_per_point is None else f"{renders_per_point:.1f}",
    ]


HEADER = (
    "",
    "measured / asked",
    "3-D RMS %",
    *(f"{b} RMS % (measured/asked)" for b in BANDS),
    "vergence error median / RMS, deg",
    "false fixations of ok; wrong matches of all",
    "failures by cause",
    "renders per point",
)


def _renders(runs: Sequence[dict[str, Any]]) -> float:
    """Experiment renders per target asked, over the runs."""
    asked = sum(len(_targets([p])) for p in runs)
    return sum(effort(p)["experiment_renders"] for p in runs) / max(asked, 1)


def _per_seed_rms(runs: Sequence[dict[str, Any]]) -> str:
    return spread_pct([summary(p)["error_pct_of_depth_rms"] for p in runs])


def _theory(targets: Sequence[dict[str, Any]], settings: dict[str, Any]) -> dict[str, float]:
    """(M5) over the measured targets: the depth error the correspondence error (measured,
    and the texture's Cramer-Rao spread) predicts, against the measured depth error."""
    baseline = settings["baseline_m"]
    f2 = settings["cameras"][1]["kx"]
    measured, predicted, bound, du = [], [], [], []
    for m in targets:
        fix = m["fixation"]
        if m["status"] != "ok" or fix["image_error_px"][1] is None:
            continue
        x, _, z = m["truth_head_m"]
        a1, a2 = math.atan((x + baseline / 2) / z), math.atan((baseline / 2 - x) / z)
        measured.append(100 * m["error_head_m"][2] / z)
        du.append(fix["image_error_px"][1])
        predicted.append(100 * float(rel_dz_correspondence(a1, a2, du[-1], f2)))
        if fix["match_sigma_px"] is not None:
            bound.append(100 * float(rel_dz_correspondence(a1, a2, fix["match_sigma_px"], f2)))
    return {
        "count": len(measured),
        "du_median_px": float(np.median(du)) if du else math.nan,
        "du_rms_px": _rms(du),
        "predicted_rms_pct": _rms(predicted),
        "bound_rms_pct": _rms(bound),
        "measured_depth_rms_pct": _rms(measured),
    }


def natural_field() -> str:
    """natural_field over seeds beside its marker twin, by texture class, and (M5)."""
    field, twin = _runs("natural_field"), _runs("natural_field_markers")
    targets, marked = _targets(field), _targets(twin)
    rows = [
        ["markerless (`natural_field`)", *_row(targets, _renders(field))],
        ["markers on the same points (`natural_field_markers`)", *_row(marked, _renders(twin))],
    ]
    classes: dict[str, list[dict[str, Any]]] = {c: [] for c in TEXTURES}
    for m in targets:
        classes.setdefault(m["texture_class"], []).append(m)
    by_texture = [[f"`{c}`", *_row(ms, None)] for c, ms in classes.items()]
    theory = _theory(targets, field[0]["settings"])
    twin_depth = _theory_depth(marked)
    predicted = theory["predicted_rms_pct"]
    return (
        f"`natural_field` on the realistic head, {seeds_label()} (each seed its own room, "
        f"clutter, targets and calibration), {len(targets)} targets asked in all; every "
        "cell pools the seeds' targets:\n\n"
        + table(HEADER, rows)
        + f"\nThe whole field's RMS seed by seed, median (min-max): markerless "
        f"{_per_seed_rms(field)}; markers {_per_seed_rms(twin)}.\n\nBy texture class "
        "(markerless; the class of the surface under the target, `occluded` when part of "
        "the template's patch is hidden from one eye):\n\n"
        + table(HEADER[:-1], (r[:-1] for r in by_texture))
        + f"\nThe theory, (M5) over the {theory['count']} measured targets: camera 2's "
        f"correspondence error was {num(theory['du_median_px'])} px median "
        f"({num(theory['du_rms_px'])} px RMS), which predicts {num(predicted)} % of depth RMS; "
        f"the texture's Cramer-Rao spread (M4) predicts {num(theory['bound_rms_pct'])} %. "
        f"Their depth error was {num(theory['measured_depth_rms_pct'])} % RMS; the markers on "
        f"the same points {num(twin_depth)} %, and the two in quadrature "
        f"{num(math.hypot(predicted, twin_depth))} %.\n"
    )


def _theory_depth(targets: Sequence[dict[str, Any]]) -> float:
    """Depth error RMS, % of depth, of the measured targets."""
    return _rms(
        [100 * m["error_head_m"][2] / m["truth_head_m"][2] for m in targets if m["status"] == "ok"]
    )


#: The room's procedures beside their marker equivalents: (label, scenario, overrides).
PROCEDURES = (
    ("Model 2 (`natural_field`)", "natural_field", {}),
    ("Model 1 (`natural_field_model1`)", "natural_field_model1", {}),
    (
        "one-step fixation, independent eyes (`natural_field_fixation`)",
        "natural_field_fixation",
        {},
    ),
)
#: The failure modes' scenarios (listed targets on chosen surfaces, each with a control).
FAILURE_MODES = ("low_texture", "repetitive_texture", "occluded_clutter")


def room_procedures() -> str:
    """Model 2, Model 1 and the one-step fixation on the room, and the textured pursuit
    beside a marker on the same path."""
    rows = []
    for label, scenario, overrides in PROCEDURES:
        runs = tuple(payload(scenario, seed=seed, **overrides) for seed in SEEDS)
        rows.append([label, *_row(_targets(runs), _renders(runs))])
    marker_eyes = [payload("independent_eyes", seed=seed) for seed in SEEDS]
    eyes = [m for p in marker_eyes for m in p["measurements"]]
    eyes_ok = [m["error_pct_of_depth"] for m in eyes if m["status"] == "ok"]
    pursuit = []
    for body in ("crate", "marker_red"):
        e = [_pursuit(body, seed) for seed in SEEDS]
        pursuit.append(
            (
                "textured box, markerless" if body == "crate" else "a marker on the same path",
                " / ".join(f"{1e3 * x['position_rms_m']:.2f}" for x in e),
                " / ".join(f"{x['position_rms_pct_of_depth']:.2f}" for x in e),
                f"{min(x['frames_present'] for x in e)}-{max(x['frames_present'] for x in e)} of "
                f"{e[0]['frames']}",
                " / ".join(num(x["vergence_error_median_deg"], 4) for x in e),
            )
        )
    return (
        f"The room of `natural_field` (realistic head), {seeds_label()}, every target asked "
        "counted:\n\n"
        + table(HEADER, rows)
        + f"\nThe same independent-eyes head on markers (`independent_eyes`, its own targets): "
        f"{len(eyes_ok)} of {len(eyes)} measured, 3-D RMS {num(_rms(eyes_ok))} %.\n\n"
        "`pursuit_textured` (ideal head, 3 s at 0.3 m/s about 1 m away), seed by seed:\n\n"
        + table(
            (
                "",
                "position RMS, mm",
                "% of distance",
                "frames with the target",
                "vergence error median, deg",
            ),
            pursuit,
        )
    )


@functools.cache
def _pursuit(body: str, seed: int) -> dict[str, Any]:
    """``pursuit_textured``'s experiment at ``seed``, pursuing ``body``: its crate, or a
    marker on the same path (the crate then taken out of the room)."""
    import tomllib

    from headsim.runs.runner import run_scenario
    from headsim.runs.serialise import results_payload
    from headsim.scenario.loading import scenario_from_document

    doc = tomllib.loads((ROOT / "scenarios" / "pursuit_textured.toml").read_text())
    if body != "crate":
        room = doc["scene"]["room"]
        room["objects"] = [o for o in room["objects"] if o["name"] != "crate"]
        doc["scene"]["pursuit"]["body"] = body
        for key in ("click_error_px", "band_px"):
            doc["scene"]["pursuit"].pop(key)
    scenario = scenario_from_document(doc, "pursuit_textured", seed=seed)
    return dict(results_payload(run_scenario(scenario))["experiment"])


def failure_modes() -> str:
    """The failure modes' scenarios: each class's targets over the seeds, every one counted."""
    rows = []
    for scenario in FAILURE_MODES:
        targets = _targets(tuple(payload(scenario, seed=seed) for seed in SEEDS))
        for cls in TEXTURES:
            group = [m for m in targets if m["texture_class"] == cls]
            if group:
                rows.append([f"`{scenario}`: `{cls}`", *_row(group, None)[:-1]])
    return (
        f"{seeds_label()}, listed targets on chosen surfaces (the textured control in each "
        "file is the `rich` row):\n\n" + table(HEADER[:-1], rows)
    )


GENERATORS: dict[str, Callable[[], str]] = {
    "natural_field": natural_field,
    "room_procedures": room_procedures,
    "failure_modes": failure_modes,
}
