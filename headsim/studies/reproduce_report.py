"""``headsim reproduce``'s report: the main figure (the paper's figures beside ours) and
report.md's text."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from headsim.studies.catalogue import (
    REALISTIC_BOARD_JOB,
    SCENARIO_JOBS,
    STUDY_JOB,
    TABLES_SCOPE,
    JobOutcome,
)
from headsim.studies.checks import (
    PAPER_ALPHA_E,
    PAPER_SIDE_MEAN_MM,
    PAPER_SIDE_STD_MM,
    TRUE_SIDE_MM,
)
from headsim.studies.render_clock import CLOCK_RENDERS
from headsim.studies.reproduce_rows import ROWS, Row, initial_direction_rows


def main_figure(
    outcomes: dict[str, JobOutcome], calibration: dict[str, Any] | None, path: Path
) -> Path | None:
    """The report's main figure: the paper's figures beside ours, one panel per experiment."""
    from headsim.studies import plots  # Agg backend

    plt = plots.plt
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
    width = 0.38

    ax = axes[0]
    ax.set_title("Initial directions (Sec. V)")
    if calibration is not None:
        ours = calibration["block"]["alpha_e_rad"]
        std = calibration["block"]["alpha_e_std_rad"]
        xs = range(2)
        ax.bar(
            [x - width / 2 for x in xs],
            [1e3 * a for a in PAPER_ALPHA_E],
            width,
            label="paper",
            color="grey",
        )
        ax.bar(
            [x + width / 2 for x in xs],
            [1e3 * a for a in ours],
            width,
            yerr=[3e3 * s for s in std],
            label="ours (3 std)",
            color="tab:blue",
        )
        ax.set_xticks(list(xs), ["alpha_e1", "alpha_e2"])
        ax.set_ylabel("mrad")
        ax.legend(fontsize=8)

    ax = axes[1]
    ax.set_title("Chessboard squares (Tables III-IV)")
    board = outcomes.get("chessboard")
    if board is not None and board.status != "error":
        e = board.data["results"]["experiment"]
        widths = [1e3 * w for w in e.get("widths_m", []) + e.get("heights_m", []) if w is not None]
        if widths:
            ax.hist(
                widths,
                bins=15,
                color="tab:blue",
                alpha=0.8,
                label=f"paper preset, {len(widths)} sides",
            )
        real = outcomes.get(REALISTIC_BOARD_JOB)
        if real is not None and real.status != "error":
            r = real.data["results"]["experiment"]
            sides = [
                1e3 * w for w in r.get("widths_m", []) + r.get("heights_m", []) if w is not None
            ]
            if sides:
                ax.hist(
                    sides,
                    bins=15,
                    color="tab:orange",
                    alpha=0.6,
                    label=f"realistic preset, {len(sides)} sides",
                )
        ax.axvspan(
            PAPER_SIDE_MEAN_MM - PAPER_SIDE_STD_MM,
            PAPER_SIDE_MEAN_MM + PAPER_SIDE_STD_MM,
            color="grey",
            alpha=0.15,
            label="paper mean +- std",
        )
        ax.axvline(PAPER_SIDE_MEAN_MM, color="grey", lw=2, label="paper mean 30.3")
        ax.axvline(TRUE_SIDE_MM, color="black", ls=":", label="true 30.0")
        ax.set_xlabel("side, mm")
        ax.legend(fontsize=8)

    ax = axes[2]
    ax.set_title("Stereo vs active (Tables V-VI)")
    ax.set_yscale("log")
    study_outcome = outcomes.get(STUDY_JOB)
    if study_outcome is not None and study_outcome.status != "error":
        rows = [
            r
            for r in study_outcome.data.get("summary", [])
            if r.get("condition") in ("as calibrated", "zoom 1.5x") and r.get("group") == "paper"
        ]
        methods = sorted(
            {r["method"] for r in rows},
            key=lambda m: list(plots.STYLE).index(m) if m in plots.STYLE else 99,
        )
        for offset, label in ((-width / 2, "as calibrated"), (width / 2, "zoom 1.5x")):
            values = [
                next(
                    (r["rms_mm"] for r in rows if r["method"] == m and r["condition"] == label),
                    math.nan,
                )
                for m in methods
            ]
            ax.bar([i + offset for i in range(len(methods))], values, width, label=label)
        ax.set_xticks(
            range(len(methods)),
            [m.replace("active_", "a_") for m in methods],
            rotation=30,
            fontsize=7,
        )
        ax.set_ylabel("RMS 3-D error, mm")
        ax.legend(fontsize=8)

    ax = axes[3]
    ax.set_title("Relative positioning, tracking")
    labels, values, colours = [], [], []
    rel = outcomes.get("relative_positioning")
    if rel is not None and rel.status != "error":
        e = rel.data["results"]["experiment"]
        labels.append("areas right\n(paper 6/6)")
        values.append(100.0 * e.get("agree", 0) / max(len(e.get("objects", [])), 1))
        colours.append("tab:blue")
    track = outcomes.get("tracking")
    if track is not None and track.status != "error":
        records = track.data["results"].get("measurements", [])
        labels.append("fixations ok\n(tracking)")
        values.append(100.0 * sum(m.get("status") == "ok" for m in records) / max(len(records), 1))
        colours.append("tab:green")
    ax.bar(labels, values, color=colours)
    ax.set_ylim(0, 105)
    ax.set_ylabel("%")
    fig.tight_layout()
    return plots._save(fig, path)


def _table(rows: list[Row]) -> list[str]:
    lines = ["| quantity | paper | ours | verdict |", "|---|---|---|---|"]
    lines += [f"| {r.quantity} | {r.paper} | {r.ours} | {r.verdict} |" for r in rows]
    return lines


Section = tuple[str, str, list[Row] | None, JobOutcome | None]


def report_sections(
    state: dict[str, Any], outcomes: dict[str, JobOutcome], calibration: dict[str, Any] | None
) -> list[Section]:
    """Per experiment: name, title, its rows (None: no result) and its outcome."""
    sections: list[tuple[str, str, list[Row] | None, JobOutcome | None]] = []
    check = outcomes.get("initial_directions")
    if calibration is not None:
        sections.append(
            (
                "initial_directions",
                SCENARIO_JOBS["initial_directions"][1],
                initial_direction_rows(
                    calibration, check.data if check and check.status != "error" else None
                ),
                check,
            )
        )
    else:
        sections.append(("initial_directions", SCENARIO_JOBS["initial_directions"][1], None, check))
    for name in (*list(SCENARIO_JOBS)[1:], STUDY_JOB, *state["sweeps"]):
        title = (
            SCENARIO_JOBS[name][1]
            if name in SCENARIO_JOBS
            else (
                "Sec. VI-B, Tables V-VI, Fig. 11: stereo against the active method; focal length x1.5"
                if name == STUDY_JOB
                else f"Insensitivity sweep {name.removeprefix('sweep_')} (beyond the paper)"
            )
        )
        outcome = outcomes.get(name)
        rows = None
        if outcome is not None and outcome.status != "error":
            data = outcome.data
            if name == "chessboard":
                beside = outcomes.get(REALISTIC_BOARD_JOB)
                realistic = beside.data if beside is not None and beside.status != "error" else None
                data = {**data, "realistic": realistic}
            try:
                rows = ROWS[name](data) if name in ROWS else []
            except (KeyError, TypeError, ValueError) as err:
                rows = None
                outcome = JobOutcome(name, "error", outcome.wall_s, error=f"report: {err!r}")
        sections.append((name, title, rows, outcome))
    return sections


def report_text(
    state: dict[str, Any],
    outcomes: dict[str, JobOutcome],
    calibration: dict[str, Any] | None,
    figure: Path | None,
) -> str:
    """The report: its count of rows reproduced first, head, seed, then per experiment the
    paper's figures beside ours."""
    sections = report_sections(state, outcomes, calibration)
    lines = [
        f"# headsim reproduce: {verdict_line(sections)}",
        "",
        "The paper's Sec. VI on one head. A row is reproduced when our figure agrees with the "
        "paper's within the bound its verdict states.",
        "",
        f"- status: **{state['status']}**",
        f"- head: the `paper` preset (the paper's Zhang intrinsics, radial distortion, initial "
        f"directions; image noise 1 grey level), hash `{(calibration or {}).get('head_hash', '?')[:12]}`",
        f"- seed: {state['seed']}; {'fast variants' if state['fast'] else 'full size'}; "
        f"{state['workers']} worker(s)",
        "- one calibration: `head.json` "
        + (
            f"({calibration['block']['fixated']} of {calibration['block']['targets']} ball positions, "
            f"{calibration['block']['render_counts']['total']} renders, {calibration.get('wall_s', math.nan):.1f} s), used by "
            "every scenario experiment"
            if calibration
            else "(not made)"
        ),
        f"- wall time {state['wall_s']:.1f} s = {state['wall_over_render']:.0f} x the median "
        f"640x480 render ({1e3 * state['render_s']:.1f} ms, measured in this run: "
        + (
            f"the quieter of the medians of {CLOCK_RENDERS[0]} renders before the workers' "
            f"first jobs, {1e3 * state.get('render_before_s', state['render_s']):.1f} ms, "
            f"and {CLOCK_RENDERS[1]} after they ended, {1e3 * state['render_after_s']:.1f} ms)"
            if state.get("render_after_s")
            else f"{CLOCK_RENDERS[0]} renders before the workers' first jobs)"
        ),
    ]
    if state.get("cpu_over_render_cpu"):
        lines.append(
            f"- CPU time {state['cpu_s']:.1f} s (this process and its workers) = "
            f"{state['cpu_over_render_cpu']:.0f} x one render's CPU time "
            f"({1e3 * state['render_cpu_s']:.1f} ms); the wall ratio is this times the "
            "cores one render keeps busy over the cores the run keeps busy"
        )
    lines.append("")
    if figure is not None:
        lines += [f"![the paper's figures beside ours]({figure.relative_to(state['out'])})", ""]
    for name, title, rows, outcome in sections:
        lines.append(f"## {title}")
        lines.append("")
        if outcome is None and rows is None:
            lines += [
                "not run" + (" (interrupted)" if state["status"] == "interrupted" else ""),
                "",
            ]
            continue
        if outcome is not None and outcome.status == "error":
            lines += [
                f"**FAILED**: {outcome.error.splitlines()[-1] if outcome.error else 'no result'}",
                "",
            ]
            continue
        if rows:
            lines += _table(rows)
        if name == "chessboard":
            beside = outcomes.get(REALISTIC_BOARD_JOB)
            lines += [
                "",
                "The paper preset's head has ideal mechanics and uses `head.json`; the realistic "
                "preset's (real tolerances, as the paper's rig had) is the same board with the "
                "chessboard scenario's own calibration, files in `chessboard_realistic/`"
                + (f" ({beside.wall_s:.1f} s)" if beside is not None else " (not run)")
                + (f": **FAILED**: {beside.error}" if beside and beside.status == "error" else "")
                + ".",
            ]
        if name == STUDY_JOB:
            lines += ["", TABLES_SCOPE]
            data = outcome.data if outcome is not None else {}
            if "renders" in data:
                lines += [
                    "",
                    f"{data['renders']} renders: Zhang's calibration "
                    f"{data['zhang']['renders']}, the fixed points and their Sec. V "
                    f"calibration {data['fixed_point']['renders']}, the rest measuring. "
                    "The fixed-point methods' Sec. V calibration uses "
                    f"{data['fixed_point'].get('targets', '?')} ball positions, fewer than "
                    "head.json's (their rows are the zoom's after/before ratios; "
                    "`headsim study` calibrates them with as many as the head).",
                ]
        if outcome is not None:
            where = f"`{name}/`" if name in SCENARIO_JOBS else "`study/`"
            lines += ["", f"{outcome.wall_s:.1f} s; files in {where}"]
        lines.append("")
    lines += ["## Verdict", "", verdict_line(sections) + ".", ""]
    return "\n".join(lines)


def verdict_line(sections: list[Section]) -> str:
    """'N of M rows reproduced, K not reproduced or failed, J without a paper figure to
    compare': a failed experiment counts as one row."""
    verdicts: list[str] = []
    for _, _, rows, outcome in sections:
        if outcome is not None and outcome.status == "error":
            verdicts.append("failed")
        elif rows:
            verdicts += [r.verdict for r in rows]
    reproduced = sum(v.startswith("reproduced") for v in verdicts)
    missed = sum(v.startswith("not reproduced") or v == "failed" for v in verdicts)
    return (
        f"{reproduced} of {len(verdicts)} rows reproduced, {missed} not reproduced or failed, "
        f"{len(verdicts) - reproduced - missed} without a paper figure to compare"
    )
