"""The documentation's figures of the realistic head: the forward model's and the rendered ones."""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from figures_common import (
    band_rms,
    benchmark,
    calibration_errors,
    num,
    payload,
    span,
    summary,
    table,
)

#: ``benchmarks/realistic_head.py``'s defaults: calibrations per figure, and per budget row.
FORWARD_SEEDS, FORWARD_BUDGET_SEEDS = 50, 10


@functools.cache
def _forward() -> dict[str, Any]:
    """Every figure of ``benchmarks/realistic_head.py`` (the exact forward model, seconds)."""
    rh = benchmark("realistic_head")
    p = rh.targets()
    head = rh.realistic()
    return {
        "field": rh.whole_field(p, FORWARD_SEEDS),
        "uncorrected": list(rh.uncorrected(p).values()),
        "principal": rh.principal_columns_change(p),
        "uniform": rh.recovery_figures(head, FORWARD_SEEDS, "uniform"),
        "near_far": rh.recovery_figures(head, FORWARD_SEEDS, "near_far"),
        "budget": rh.budget_conditions(p[:500], FORWARD_BUDGET_SEEDS),
    }


def _mm(value_m: float, digits: int = 3) -> str:
    return f"{1e3 * value_m:.{digits}f}"


def _baseline_cell(fit: dict[str, Any]) -> str:
    b = fit["baseline"]
    return f"{_mm(b['rms_m'])} / {_mm(b['max_m'])} mm; {_mm(b['std_m'])} mm; {b['z_spread']:.2f}"


def forward_field() -> str:
    """The forward model's figures table, and what it says of each eye's offset."""
    f = _forward()
    field = f["field"]
    med = np.median(field, axis=0)
    offset_n, _, offset_all = f["uncorrected"]
    side = f["uncorrected"][1]
    uni, nf = f["uniform"], f["near_far"]
    uo, no = uni["offsets"], nf["offsets"]
    rows = [
        (
            f"3-D error RMS after the extended calibration, all targets (median over "
            f"{FORWARD_SEEDS} calibrations; 95th pct)",
            f"{med[0]:.3f} % ({np.percentile(field[:, 0], 95):.3f} %)",
        ),
        (
            "... by depth band 0.3-0.6 / 0.6-1.0 / 1.0-1.5 m",
            " / ".join(f"{m:.3f}" for m in med[1:]) + " %",
        ),
        *(
            (
                label,
                f"{u['depth_pct']:.3f} % vs {u['predicted_pct']:.3f} % (ratio "
                f"{u['depth_pct'] / u['predicted_pct']:.2f})",
            )
            for label, u in (
                (
                    "offsets left uncorrected, n = 20 mm at the paper cameras' columns: depth error "
                    "RMS vs first-order `\\|dD_eff\\|/D`",
                    offset_n,
                ),
                ("offsets and baseline error of the realistic head uncorrected", offset_all),
            )
        ),
        (
            "goal columns at the principal points, n = 20 mm alone: change of any x, z estimate",
            f"{f['principal'][0]:.2g} m",
        ),
        (
            f"effective baseline error over {FORWARD_SEEDS} calibrations: RMS / max; stated std; "
            "z-score spread",
            _baseline_cell(uni),
        ),
        (
            "each eye's offset error, depths uniform in 0.25-1.5 m: RMS / max; stated std; "
            "z-score spread",
            f"{span(1e3 * o['rms_m'] for o in uo)} / {span(1e3 * o['max_m'] for o in uo)} mm; "
            f"{span(1e3 * o['std_m'] for o in uo)} mm; {span(o['z_spread'] for o in uo)}",
        ),
        (
            f"each eye's offset error, `near_far` ({nf['near_balls']} balls at 0.25 m, "
            f"{60 - nf['near_balls']} at 1.5 m): RMS s1 / s2; max; stated std; z-score spread; "
            "within 1 stated std",
            f"{_mm(no[0]['rms_m'])} / {_mm(no[1]['rms_m'])} mm; "
            f"{_mm(max(o['max_m'] for o in no), 2)} mm; {_mm(no[0]['std_m'])} mm (eq. above: "
            f"{_mm(nf['limit_m'])}); {no[0]['z_spread']:.2f} / {no[1]['z_spread']:.2f}; "
            f"{no[0]['within_1_std_pct']:.0f} / {no[1]['within_1_std_pct']:.0f} %",
        ),
        (
            "effective baseline with `near_far`: RMS / max; stated std; z-score spread",
            _baseline_cell(nf),
        ),
    ]
    uniform_mm = np.mean([1e3 * o["rms_m"] for o in uo])
    near_far_mm = np.mean([1e3 * o["rms_m"] for o in no])
    return table(("figure", "value"), rows) + (
        f"\nWith the depths uniform, each eye's own offset is known to about {uniform_mm:.2f} mm "
        f"(1 sigma; eq. above: {_mm(uni['limit_m'], 2)} mm): the information limit of that "
        f"layout. The `near_far` layout halves it ({near_far_mm:.2f} mm over {FORWARD_SEEDS} "
        "seeds), with the fit's stated standard errors matching the scatter. The effective "
        f"baseline, which is what depth needs, is known to {_mm(uni['baseline']['rms_m'], 2)} mm "
        f"either way. (Sideways offsets alike in both eyes, {_mm(side['s1_m'], 0)} mm each, "
        f"cancel in the effective baseline: depth error {side['depth_pct']:.3f} %, x error "
        f"{side['x_pct']:.3f} % of depth.)\n"
    )


#: The results page's names of ``realistic_head.budget_conditions``' rows, in its order.
FORWARD_BUDGET_ROWS = (
    "realistic, all on",
    "optical-centre offsets off",
    "baseline error off",
    "count error off",
    "tape noise off",
    "offsets not corrected (extended directions, s = 0)",
    "Sec. V only (no extension)",
)


def forward_budget() -> str:
    """The forward model's error budget table (median over its calibrations)."""
    rows = (
        (name, num(c["rms_3d_pct"]), num(c["rms_depth_pct"]), num(c["predicted_depth_pct"]))
        for name, c in zip(FORWARD_BUDGET_ROWS, _forward()["budget"], strict=True)
    )
    return table(("condition", "3-D RMS %", "depth RMS %", "eqs. 15-18 %"), rows)


# --- the rendered head: the error budget and the two calibration layouts ------------

#: The rendered budget's and the layouts' size: calibration balls and measured targets of
#: ``realistic_field`` (60 and 60 in the scenario; smaller here, so that CI regenerates them).
BALLS, TARGETS = 40, 20
#: The seeds of the layouts' comparison.
LAYOUT_SEEDS = (0, 1, 2)


def _sized(overrides: dict[str, Any]) -> dict[str, Any]:
    return {
        **overrides,
        "experiment.calibration.targets": BALLS,
        "scene.random_targets.count": TARGETS,
    }


@functools.cache
def _budget_row(name: str, layout: str = "uniform") -> dict[str, Any]:
    """One row of ``headsim.studies.error_budget`` at this module's size (seed 0)."""
    from headsim.studies.error_budget import CONDITIONS, BudgetCondition, run_condition

    (condition,) = (c for c in CONDITIONS if c.name == name)
    overrides = _sized(condition.overrides)
    if layout != "uniform":
        overrides["experiment.calibration.layout"] = layout
    return run_condition(
        BudgetCondition(condition.name, condition.group, overrides), fast=False, seed=0
    )


def _table_lines(rows: list[dict[str, Any]]) -> str:
    """``error_budget.markdown_table``'s table alone (not its title or note)."""
    from headsim.studies.error_budget import markdown_table

    lines = markdown_table(rows, fast=False).splitlines()
    return "\n".join(line for line in lines if line.startswith("|")) + "\n"


def budget() -> str:
    """The rendered error budget, every row, and what it shows."""
    from headsim.studies.error_budget import CONDITIONS

    rows = [_budget_row(c.name) for c in CONDITIONS]
    by = {r["condition"]: r for r in rows}
    ref = by["realistic, everything on"]
    single = sorted(
        (
            r
            for r in rows[1:]
            if r["group"] == "imperfection off" and r["condition"] != "every imperfection off"
        ),
        key=lambda r: r["rms_3d_pct"],
    )
    top, *next_three = single[:4]
    not_fitted = by["line-of-sight offsets not fitted"]
    bare = by["not fitted, optical-centre offsets off"]
    near_on = _budget_row("realistic, everything on", "near_far")
    near_off = _budget_row("line-of-sight offsets not fitted", "near_far")

    def off(r: dict[str, Any]) -> str:
        return r["condition"].removesuffix(" off")

    return (
        f"{BALLS} calibration balls and {TARGETS} targets per row (seed 0):\n\n"
        + _table_lines(rows)
        + f"\nWhat it shows: with both extensions on, no single imperfection dominates; "
        f"{off(top)} is the largest (off: {num(ref['rms_3d_pct'])} -> {num(top['rms_3d_pct'])} %), "
        f"then {', '.join(off(r) for r in next_three[:-1])} and {off(next_three[-1])} "
        f"({' / '.join(num(r['rms_3d_pct']) for r in next_three)} % with each off); everything "
        f"off leaves {num(by['every imperfection off']['rms_3d_pct'])} %. Without the "
        f"line-of-sight fit the realistic offsets and baseline error cost "
        f"{num(not_fitted['rms_3d_pct'])} % (x-z {num(not_fitted['rms_xz_pct'])} %, eqs. 17/19: "
        f"{num(not_fitted['predicted_xz_pct'])} %, ratio "
        f"{not_fitted['rms_xz_pct'] / not_fitted['predicted_xz_pct']:.2f}), and with the offsets "
        f"off too, only the baseline's 0.3 mm is left uncorrected: x-z {num(bare['rms_xz_pct'])} % "
        f"against {num(bare['predicted_xz_pct'])} % "
        f'({bare["rms_xz_pct"] / bare["predicted_xz_pct"]:.2f}). With `layout = "near_far"` the '
        f"same budget gives {num(near_on['rms_3d_pct'])} % with everything on but "
        f"{num(near_off['rms_3d_pct'])} % with the offsets not fitted (prediction "
        f"{num(near_off['predicted_xz_pct'])} % x-z).\n"
    )


def _layout_run(seed: int, layout: str) -> dict[str, Any]:
    return payload(
        "realistic_field", seed=seed, **_sized({"experiment.calibration.layout": layout})
    )


def layouts() -> str:
    """The two calibration layouts rendered: same seeds, same targets."""
    rows, offset_rms, field_rms = [], [], []
    for layout, label in (
        ("uniform", "uniform in 0.25-1.5 m (the default)"),
        ("near_far", "`near_far`"),
    ):
        runs = [_layout_run(seed, layout) for seed in LAYOUT_SEEDS]
        rms = [summary(p)["error_pct_of_depth_rms"] for p in runs]
        near = [band_rms(summary(p))[0] for p in runs]
        errors = [calibration_errors(p) for p in runs]
        offsets = np.array([e["offsets_mm"] for e in errors]).ravel()
        baseline = np.array([e["baseline_mm"] for e in errors])
        offset_rms.append(float(np.sqrt(np.mean(offsets**2))))
        field_rms.append(float(np.mean(rms)))
        rows.append(
            (
                label,
                f"{np.mean(rms):.3f} % ({span(rms, 3)})",
                f"{np.mean(near):.3f} %",
                f"{np.sqrt(np.mean(offsets**2)):.2f} mm",
                f"{np.sqrt(np.mean(baseline**2)):.3f} mm",
                f"{span((e['fixated'] for e in errors), 0)} of {errors[0]['targets']}",
            )
        )
    n = len(LAYOUT_SEEDS)
    return (
        f"{BALLS} balls and {TARGETS} targets per run, seeds {span(LAYOUT_SEEDS, 0)}:\n\n"
        + table(
            (
                "layout",
                f"3-D RMS, all targets (mean of {n}; range)",
                "0-0.6 m band (mean)",
                f"offsets' error RMS ({2 * n} values)",
                "effective baseline error RMS",
                "balls fixated",
            ),
            rows,
        )
        + f"\n`near_far` cuts each eye's offset error to {offset_rms[1] / offset_rms[0]:.2f} "
        f"times the uniform layout's here (the forward model's, {FORWARD_SEEDS} seeds of 60 "
        f"balls: {_forward_offset_ratio():.2f}); the whole-field RMS is {field_rms[1]:.3f} % "
        f"against {field_rms[0]:.3f} %.\n"
    )


def _forward_offset_ratio() -> float:
    """The forward model's offset error RMS with ``near_far`` over the uniform layout's."""
    f = _forward()
    rms = [
        np.sqrt(np.mean([o["rms_m"] ** 2 for o in f[k]["offsets"]]))
        for k in ("near_far", "uniform")
    ]
    return float(rms[0] / rms[1])
