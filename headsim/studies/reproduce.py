"""``headsim reproduce``: every experiment of the paper's Sec. VI on one head, in one report.

One head (the scenarios' ``paper`` head) is calibrated once (Sec. V, the
``calibration`` scenario's targets) into ``DIR/head.json``; then, spread over
``--workers`` processes, each experiment runs with that calibration:

- ``initial_directions``: the calibration's check targets, before and after
  (Sec. V, Fig. 8), beside the calibrated directions;
- ``chessboard``: every cross point of a 30 mm board (Sec. VI-A, Tables III-IV);
- ``relative_positioning``: the cross point and six objects' areas (Sec. VI-C, Table VII);
- ``tracking``: the moving target with the neck (beyond Sec. VI's static tests);
- ``tables_v_vi``: calibrated stereo against the active method (Sec. VI-B,
  Tables V-VI, Fig. 11), then the cameras zoomed 1.5x with every calibration
  kept (the changed focal length), on the same head with the same Sec. V
  calibration (head.json), one Zhang stereo calibration and one zoom
  fixed-point calibration (:mod:`headsim.studies.paper_tables`; the study's other
  heads and changes are left to ``python -m headsim.studies.study``).

The head's calibration, Zhang's and the fixed points' run first, side by
side; then the longest experiments first, so that the workers finish together.
With ``--sweeps`` the study's insensitivity sweeps are added.  Every
experiment writes its files under ``DIR/<experiment>/`` as it finishes, and
``DIR/report.md`` (with ``DIR/figures/*.png``) is rewritten after each one, so
an interrupted run leaves a readable partial report.  A failed experiment is
reported as such beside the others.
"""

from __future__ import annotations

import concurrent.futures as futures
import contextlib
import dataclasses
import functools
import importlib
import math
import multiprocessing
import os
import resource
import signal
import statistics
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from headsim.errors import BadInput, OutputNotWritable
from headsim.run.progress import Status, quiet
from headsim.run.results import to_jsonable, write_json_atomic, write_text_atomic

#: The scenarios run with the one calibration, and what each reproduces.
SCENARIO_JOBS = {
    "initial_directions": ("calibration", "Sec. V, Fig. 8: initial directions"),
    "chessboard": ("chessboard", "Sec. VI-A, Tables III-IV, Fig. 10: chessboard"),
    "relative_positioning": (
        "relative_positioning",
        "Sec. VI-C, Table VII, Fig. 12: relative positioning",
    ),
    "tracking": ("tracking", "Tracking with the neck (Model 1), beyond the paper"),
}
STUDY_JOB = "tables_v_vi"
#: What the Tables V/VI experiment measures here, and what it leaves to the study.
TABLES_SCOPE = (
    "Measured on this head with `head.json` (the image-centre active methods), one Zhang "
    "calibration (stereo) and one zoom fixed-point calibration (the fixed-point methods, "
    "beyond the paper, fewer ball positions than head.json): the six target positions, as calibrated and with the focal length "
    "x1.5. The three image-centre methods servo once and are computed from the same images. "
    "Smaller than `python -m headsim.studies.study --experiment compare`, which also measures a "
    "second head with centred principal points and the 0.7x zoom, principal-point and k1 "
    "changes (beyond the paper's tables)."
)
#: Ball positions of the fixed-point methods' Sec. V calibration (beyond the paper), at
#: most: half of head.json's 60.  Their rows are the zoom's after/before ratios, which
#: the calibration's precision hardly moves (seed 0: 0.82 -> 0.85 and 1.51 -> 1.65
#: with 60 -> 30), and it halves the run's third-longest job (524 -> 248 renders).
FIXED_POINT_TARGETS = 30
#: The scenario whose head (and calibration) every experiment uses.
TABLES_HEAD = "calibration"
#: Paper's figures (Sec. VI).
PAPER_ALPHA_E = (0.0578, -0.0254)
PAPER_SIDE_MEAN_MM, PAPER_SIDE_STD_MM, TRUE_SIDE_MM = 30.3, 0.677, 30.0
#: "Very close to stereovision" (Sec. VI-B) read as: RMS error at most this times stereo's.
CLOSE_TO_STEREO = 2.0
#: "Insensitive to the intrinsic parameters" read as: RMS after the zoom at most this times before.
INSENSITIVE = 2.0


class ReproduceError(BadInput, ValueError):
    """Bad input for ``headsim reproduce`` (exit 2)."""


@dataclass
class JobOutcome:
    """What one experiment returned: ``status`` "ok", "failed" (ran, a check failed) or "error"."""

    name: str
    status: str
    wall_s: float
    data: dict[str, Any] = field(default_factory=dict)
    error: str = ""


# -- jobs (run in worker processes; module-level so they pickle) ---------------------


class JobError(RuntimeError):
    """An experiment failed in its worker; the message says why (picklable, unlike
    some of the errors it stands for: a worker must not break the pool)."""


def _plain_errors(job: Callable[..., dict[str, Any]]) -> Callable[..., dict[str, Any]]:
    @functools.wraps(job)
    def run(*args: Any) -> dict[str, Any]:
        began, cpu = time.time(), time.process_time()
        try:
            data = job(*args)
        except Exception as err:
            raise JobError(_why(err)) from None
        # Where and when it ran (report.json's timeline: the critical path).
        data["worker"] = {
            "pid": os.getpid(),
            "start": began,
            "end": time.time(),
            "cpu_s": time.process_time() - cpu,
        }
        return data

    return run


@_plain_errors
def _calibrate_job(out: str, fast: bool, seed: int | None) -> dict[str, Any]:
    from headsim.active.calibration_file import head_hash, write_calibration
    from headsim.run.runner import calibrate_scenario
    from headsim.run.serialise import calibration_block
    from headsim.scenario.schema import load_scenario

    scenario = load_scenario("calibration", fast=fast, seed=seed)
    start = time.perf_counter()
    report = calibrate_scenario(scenario)
    wall = time.perf_counter() - start
    if not report.ok:
        raise RuntimeError(f"calibration failed: {report.status_text}")
    block = calibration_block(report)
    path = write_calibration(
        (Path(out) / "head.json").resolve(), scenario.settings, block, "calibration", scenario.seed
    )
    return {
        "path": str(path),
        "block": block,
        "head_hash": head_hash(scenario.settings),
        "seed": scenario.seed,
        "wall_s": wall,
    }


@_plain_errors
def _scenario_job(name: str, out: str, fast: bool, seed: int | None, head: str) -> dict[str, Any]:
    from headsim.run.runner import run_scenario
    from headsim.run.serialise import results_payload
    from headsim.run.summary import summary_text
    from headsim.scenario.schema import load_scenario

    scenario_name, _ = SCENARIO_JOBS[name]
    scenario = load_scenario(
        scenario_name, fast=fast, seed=seed, overrides={"experiment.calibration.from": head}
    )
    start = time.perf_counter()
    result = run_scenario(scenario)
    wall = time.perf_counter() - start
    payload = to_jsonable(results_payload(result))
    directory = Path(out) / name
    write_json_atomic(directory / "results.json", payload)
    write_text_atomic(directory / "summary.txt", summary_text(result) + "\n")
    return {
        "results": payload,
        "wall_s": wall,
        "renders": result.renders,
        "rendered_frames": result.rendered_frames,
        "points": len(result.records),
    }


def _study_config(fast: bool, seed: int | None) -> Any:
    from headsim.studies import study

    make = study.StudyConfig.quick if fast else study.StudyConfig
    return make(seed=seed or 0)


@_plain_errors
def _zhang_job(fast: bool, seed: int | None) -> dict[str, Any]:
    """Zhang's stereo calibration of the one head, once (it needs no head.json)."""
    from headsim.scenario.schema import load_scenario
    from headsim.studies.paper_tables import zhang_calibration

    scenario = load_scenario(TABLES_HEAD, fast=fast, seed=seed)
    start = time.perf_counter()
    calibration, renders = zhang_calibration(scenario.settings, _study_config(fast, seed))
    return {"calibration": calibration, "renders": renders, "wall_s": time.perf_counter() - start}


@_plain_errors
def _fixed_point_job(fast: bool, seed: int | None) -> dict[str, Any]:
    """The zoom fixed points and the Sec. V calibration on their columns, once (beyond the
    paper: the active method that the focal length's change does not move)."""
    from headsim.scenario.schema import load_scenario
    from headsim.studies.paper_tables import fixed_point_calibration

    scenario = load_scenario(TABLES_HEAD, fast=fast, seed=seed)
    start = time.perf_counter()
    config = _study_config(fast, seed)
    targets = min(config.calibration_targets, FIXED_POINT_TARGETS)
    fixed = fixed_point_calibration(
        scenario.settings, dataclasses.replace(config, calibration_targets=targets)
    )
    return {"fixed": fixed, "targets": targets, "wall_s": time.perf_counter() - start}


@_plain_errors
def _tables_job(
    out: str,
    fast: bool,
    seed: int | None,
    head: str,
    zhang: dict[str, Any],
    fixed: dict[str, Any],
) -> dict[str, Any]:
    """Tables V/VI and the changed focal length with the one calibration and Zhang's."""
    from headsim.active.calibration_file import read_calibration
    from headsim.scenario.schema import load_scenario
    from headsim.studies import paper_tables, study

    settings = load_scenario(TABLES_HEAD, fast=fast, seed=seed).settings
    stored = read_calibration(head, settings).knowledge
    calibration = zhang["calibration"]
    result = paper_tables.run_tables(
        settings, calibration, stored, _study_config(fast, seed), fixed["fixed"]
    )
    # The PNG is drawn by the parent, which loads matplotlib while the workers run.
    files = study.write_experiment(result, Path(out) / "study", figure=False)
    own = result.seconds + zhang["wall_s"] + fixed["wall_s"]
    data = to_jsonable(
        {
            "title": result.experiment.title,
            "summary": study.summary_rows(result),
            "figures": study.compare_figures(result),
            "files": {k: str(p) for k, p in files.items()},
            "seconds": own,
            "zhang": {
                "seconds": zhang["wall_s"],
                "views": calibration.views,
                "rms_px": calibration.stereo_rms_px,
                "renders": zhang["renders"],
            },
            "fixed_point": {
                "seconds": fixed["wall_s"],
                "renders": fixed["fixed"].renders,
                "targets": fixed["targets"],
                "principal_error_px": fixed["fixed"].principal.errors_px,
                "alpha_e_error_mrad": [1e3 * e for e in fixed["fixed"].calibration.alpha_e_error],
            },
            "renders": zhang["renders"]
            + fixed["fixed"].renders
            + sum(e.renders for r in result.results for e in r.errors),
        }
    )
    data["result"] = result  # for the parent to draw the PNG
    return data


@_plain_errors
def _study_job(name: str, out: str, fast: bool, seed: int | None) -> dict[str, Any]:
    from headsim.studies import study

    config = _study_config(fast, seed)
    experiment = study.sweep_experiment(name.removeprefix("sweep_"), config)
    result = study.run_experiment(experiment, config)
    files = study.write_experiment(result, Path(out) / "study")
    return to_jsonable(
        {
            "title": experiment.title,
            "summary": study.summary_rows(result),
            "figures": study.compare_figures(result) if experiment.kind == "compare" else None,
            "files": {k: str(p) for k, p in files.items()},
            "seconds": result.seconds,
        }
    )


def _cpu_s() -> float:
    """CPU time, user and system, of this process and its children that ended, s."""
    own, children = (
        resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
    )
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


class RenderClock:
    """Times 640x480 renders of the default scene in this process, while no worker of
    the run exists: the unit before they start, and a few after they ended, which
    show how the machine's load moved (reported, not used in the ratio)."""

    def __init__(self) -> None:
        from headsim.sim.settings import HeadSettings
        from headsim.sim.simulator import HeadSim

        self._sim = HeadSim("default", HeadSettings())
        self._sim.move(eye=0.05)
        for camera in (1, 2):
            self._sim.render(camera)
        self.times_s: list[float] = []
        #: CPU time of each render (all of this process's threads: llvmpipe's too), s.
        self.cpu_s: list[float] = []

    def sample(self, renders: int) -> float:
        """Time ``renders`` more renders; their median wall time, s."""
        times = []
        for _ in range(renders):
            start, cpu = time.perf_counter(), time.process_time()
            self._sim.render(1 + len(self.times_s) % 2)
            times.append(time.perf_counter() - start)
            self.cpu_s.append(time.process_time() - cpu)
        self.times_s += times
        return statistics.median(times)

    def close(self) -> None:
        self._sim.close()


#: Renders timed before the workers start (the unit) and after they end (the load's drift).
CLOCK_RENDERS = (21, 7)


# -- verdicts --------------------------------------------------------------------------


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


def chessboard_rows(data: dict[str, Any]) -> list[Row]:
    e = data["results"]["experiment"]
    mean_mm = None if e.get("side_mean_m") is None else 1e3 * e["side_mean_m"]
    std_mm = None if e.get("side_std_m") is None else 1e3 * e["side_std_m"]
    paper_error = abs(PAPER_SIDE_MEAN_MM - TRUE_SIDE_MM)
    return [
        Row(
            "square side, mean, mm (true 30)",
            f"{PAPER_SIDE_MEAN_MM}",
            _fmt(mean_mm, ".3f"),
            "reproduced (as accurate or better)"
            if mean_mm is not None and abs(mean_mm - TRUE_SIDE_MM) <= paper_error
            else "not reproduced",
        ),
        Row(
            "square side, std, mm",
            f"{PAPER_SIDE_STD_MM}",
            _fmt(std_mm, ".3f"),
            "reproduced (as precise or better)"
            if std_mm is not None and std_mm <= PAPER_SIDE_STD_MM
            else "not reproduced",
        ),
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


# -- figures and report ------------------------------------------------------------------


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
                widths, bins=15, color="tab:blue", alpha=0.8, label=f"ours, {len(widths)} sides"
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
            try:
                rows = ROWS[name](outcome.data) if name in ROWS else []
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
    """The report: head, seed, then per experiment the paper's figures beside ours."""
    lines = [
        "# headsim reproduce: the paper's Sec. VI on one head",
        "",
        f"- status: **{state['status']}**",
        f"- head: the `paper` preset (the paper's Zhang intrinsics, radial distortion, initial "
        f"directions; image noise 1 grey level), hash `{(calibration or {}).get('head_hash', '?')[:12]}`",
        f"- seed: {state['seed']}; {'fast variants' if state['fast'] else 'full size'}; "
        f"{state['workers']} worker(s)",
        "- one calibration: `head.json` "
        + (
            f"({calibration['block']['fixated']} of {calibration['block']['targets']} ball positions, "
            f"{calibration['block']['renders']} renders, {calibration.get('wall_s', math.nan):.1f} s), used by "
            "every scenario experiment"
            if calibration
            else "(not made)"
        ),
        f"- wall time {state['wall_s']:.1f} s = {state['wall_over_render']:.0f} x the median "
        f"640x480 render ({1e3 * state['render_s']:.1f} ms, measured in this run, "
        f"{CLOCK_RENDERS[0]} renders before the workers start"
        + (
            f"; {1e3 * state['render_after_s']:.1f} ms after they ended)"
            if state.get("render_after_s")
            else ")"
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
    verdicts = []
    sections = report_sections(state, outcomes, calibration)
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
            verdicts.append("failed")
            continue
        if rows:
            lines += _table(rows)
            verdicts += [r.verdict for r in rows]
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
                    "`python -m headsim.studies.study` calibrates them with as many as the head).",
                ]
        if outcome is not None:
            where = f"`{name}/`" if name in SCENARIO_JOBS else "`study/`"
            lines += ["", f"{outcome.wall_s:.1f} s; files in {where}"]
        lines.append("")
    reproduced = sum(v.startswith("reproduced") for v in verdicts)
    missed = sum(v.startswith("not reproduced") or v == "failed" for v in verdicts)
    lines += [
        "## Verdict",
        "",
        f"{reproduced} rows reproduced, {missed} not reproduced or failed, "
        f"{len(verdicts) - reproduced - missed} without a paper figure to compare.",
        "",
    ]
    return "\n".join(lines)


# -- running -------------------------------------------------------------------------------


def _render_threads(workers: int) -> int:
    """llvmpipe threads per worker: the CPUs shared among the workers (at least 1)."""
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return max(1, (cpus or 1) // workers)


def _init_worker(threads: int) -> None:
    # Ctrl-C is the parent's to handle: it stops the workers and keeps the report.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # Mesa's llvmpipe renders with one thread per CPU by default: N workers, each
    # with as many threads as the machine has CPUs, would oversubscribe it.  Read
    # when the worker's first OpenGL context is made; a user's own setting is kept.
    os.environ.setdefault("LP_NUM_THREADS", str(threads))


def _pool(workers: int) -> futures.Executor:
    # Spawned, not forked: a fork after OpenGL was used hangs (platform notes).
    return futures.ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_init_worker,
        initargs=(_render_threads(workers),),
    )


def reproduce(
    out: str | Path,
    *,
    fast: bool = False,
    workers: int = 1,
    sweeps: bool = False,
    seed: int | None = None,
    progress: Callable[[str], None] = lambda _: None,
) -> dict[str, Any]:
    """Run everything, write DIR/report.md; returns the state (``status``: ok, failed, interrupted)."""
    from headsim.studies.study import SWEEPS

    if not isinstance(workers, int) or not 1 <= workers <= 64:
        raise ReproduceError(f"--workers must be an integer from 1 to 64, got {workers!r}")
    if seed is not None and not 0 <= seed < 2**32:
        raise ReproduceError(f"--seed must be from 0 to 2**32 - 1, got {seed}")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ReproduceError(f"--out: {out} exists and is not a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputNotWritable(f"--out: cannot create {out}: {err.strerror}") from err
    start, epoch = time.perf_counter(), time.time()
    clock = RenderClock()
    render_s = clock.sample(CLOCK_RENDERS[0])
    state: dict[str, Any] = {
        "status": "running",
        "out": out,
        "fast": fast,
        "workers": workers,
        "seed": 0 if seed is None else seed,
        "sweeps": [f"sweep_{name}" for name in SWEEPS] if sweeps else [],
        "render_s": render_s,
        "wall_s": 0.0,
        "wall_over_render": 0.0,
    }
    outcomes: dict[str, JobOutcome] = {}
    calibration: dict[str, Any] | None = None
    #: Each job's worker, times since the start and CPU time, s: {"pid", "start", "end", "cpu_s"}.
    timeline: dict[str, dict[str, float]] = {"render_time": {"pid": os.getpid(), "start": 0.0}}
    timeline["render_time"]["end"] = time.time() - epoch

    def ran(name: str, data: dict[str, Any]) -> None:
        worker = data.get("worker")
        if worker:
            timeline[name] = {
                "pid": worker["pid"],
                "start": worker["start"] - epoch,
                "end": worker["end"] - epoch,
                "cpu_s": worker["cpu_s"],
            }

    def draw_tables() -> None:
        """The Tables V/VI PNG, once (drawn here, while the other workers run)."""
        tables = outcomes.get(STUDY_JOB)
        if tables is not None and "result" in tables.data:
            from headsim.studies import plots

            result = tables.data.pop("result")
            plots.plot_experiment(result, Path(tables.data["files"]["png"]))

    def write_report(figure: bool = True) -> None:
        """report.md and report.json; the main figure (matplotlib, ~1 s) only when asked:
        at the end, and when interrupted.  The wall time counts the figure."""
        drawn = None
        if figure:
            try:
                drawn = main_figure(outcomes, calibration, out / "figures" / "main.png")
                draw_tables()
            except Exception as err:  # a figure must not hide the numbers
                progress(f"figure not drawn: {err!r}")
        state["wall_s"] = time.perf_counter() - start
        state["wall_over_render"] = state["wall_s"] / state["render_s"]
        write_text_atomic(out / "report.md", report_text(state, outcomes, calibration, drawn))
        write_json_atomic(
            out / "report.json",
            to_jsonable(
                {
                    "status": state["status"],
                    "seed": state["seed"],
                    "fast": fast,
                    "workers": workers,
                    "wall_s": state["wall_s"],
                    "render_s": state["render_s"],
                    "render_after_s": state.get("render_after_s"),
                    "render_cpu_s": state.get("render_cpu_s"),
                    "cpu_s": state.get("cpu_s"),
                    "cpu_over_render_cpu": state.get("cpu_over_render_cpu"),
                    "render_samples_s": clock.times_s,
                    "wall_over_render": state["wall_over_render"],
                    "experiments": {
                        n: {"status": o.status, "wall_s": o.wall_s, "error": o.error}
                        for n, o in outcomes.items()
                    },
                    "timeline": timeline,
                    "rows": {
                        name: None
                        if rows is None
                        else [
                            {"quantity": r.quantity, "ours": r.ours, "verdict": r.verdict}
                            for r in rows
                        ]
                        for name, _, rows, _ in report_sections(state, outcomes, calibration)
                    },
                }
            ),
        )

    pool = _pool(workers)
    try:
        write_report(figure=False)
        progress("calibrating the head once (and its stereo pair, Zhang, beside it)")
        # matplotlib loads (about 1 s) while the workers run, not after them.
        threading.Thread(
            target=importlib.import_module, args=("headsim.studies.plots",), daemon=True
        ).start()
        path = str(out)
        head = lambda done: done["calibration"]["path"]  # noqa: E731
        plan = [
            _Job("calibration", _calibrate_job, (), lambda done: (path, fast, seed)),
            _Job("zhang", _zhang_job, (), lambda done: (fast, seed)),
            _Job("fixed_point", _fixed_point_job, (), lambda done: (fast, seed)),
            *(
                _Job(
                    name,
                    _scenario_job,
                    ("calibration",),
                    functools.partial(
                        lambda done, name: (name, path, fast, seed, head(done)), name=name
                    ),
                )
                for name in SCENARIO_JOBS
            ),
            _Job(
                STUDY_JOB,
                _tables_job,
                ("calibration", "zhang", "fixed_point"),
                lambda done: (
                    path,
                    fast,
                    seed,
                    head(done),
                    done["zhang"],
                    done["fixed_point"],
                ),
            ),
            *(
                _Job(
                    name,
                    _study_job,
                    (),
                    functools.partial(lambda d, n: (n, path, fast, seed), n=name),
                )
                for name in state["sweeps"]
            ),
        ]

        def finished(name: str, data: dict[str, Any] | None, error: str, wall_s: float) -> None:
            nonlocal calibration
            if name == "calibration":
                calibration = data
                if data is None:
                    outcomes["initial_directions"] = JobOutcome(
                        "initial_directions", "error", wall_s, error=error
                    )
                return
            if name in ("zhang", "fixed_point"):
                if data is None and STUDY_JOB not in outcomes:
                    outcomes[STUDY_JOB] = JobOutcome(STUDY_JOB, "error", wall_s, error=error)
                return
            if data is None:
                outcomes[name] = JobOutcome(name, "error", wall_s, error=error)
            else:
                failed = bool(data.get("results", {}).get("failures"))
                # The job's own time, not the time it waited for a worker.
                own = data.get("wall_s", data.get("seconds"))
                outcomes[name] = JobOutcome(
                    name, "failed" if failed else "ok", float(own) if own else wall_s, data
                )
            progress(f"{name}: {outcomes[name].status}")
            if name == STUDY_JOB:
                try:
                    draw_tables()
                except Exception as err:  # a figure must not hide the numbers
                    progress(f"figure not drawn: {err!r}")
            write_report(figure=False)

        def skipped(name: str, missing: str) -> None:
            if name not in outcomes:
                why = "no calibration to use" if missing == "calibration" else f"no {missing}"
                outcomes[name] = JobOutcome(name, "error", 0.0, error=why)

        ended = _schedule(pool, workers, plan, finished, skipped, ran)
        progress(f"scheduler: {ended}")
        # Every job ended and its files are written: the idle workers are stopped
        # rather than left to tear down their interpreters and GL contexts (~0.5 s).
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            process.terminate()
        state["status"] = (
            "ok" if calibration and all(o.status == "ok" for o in outcomes.values()) else "failed"
        )
    except KeyboardInterrupt:
        state["status"] = "interrupted"
        # Stop the workers now: their experiments are lost, the finished ones are kept.
        processes = list((getattr(pool, "_processes", None) or {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        # With a worker caught half-started (Ctrl-C while the pool spawned it, which
        # the pool does not know of yet), the exit would wait for it forever: every
        # child of this process is one of the pool's workers.
        for process in {*processes, *multiprocessing.active_children()}:
            process.terminate()
        write_report()
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        timeline["shutdown"] = {"pid": os.getpid(), "start": 0.0, "end": time.time() - epoch}
        try:
            if state["status"] != "interrupted":
                state["render_after_s"] = clock.sample(CLOCK_RENDERS[1])
                # CPU time of the whole run (this process and its ended workers) over
                # one render's: the machine's other load moves it less than the wall
                # ratio, which is this times the cores a render keeps busy over the
                # cores the run keeps busy.
                state["render_cpu_s"] = statistics.median(clock.cpu_s[: CLOCK_RENDERS[0]])
                state["cpu_s"] = _cpu_s()
                state["cpu_over_render_cpu"] = state["cpu_s"] / state["render_cpu_s"]
        finally:
            clock.close()
        timeline["render_time_end"] = {"pid": os.getpid(), "start": 0.0, "end": time.time() - epoch}
    write_report()
    return state


# -- scheduling ------------------------------------------------------------------------------

#: What each job costs, in 640x480 render-times at full size (measured one after the
#: other on this machine, Dec 2026): the scheduler starts the ready job with the
#: longest path to the end first.  Sweeps are the longest.
COSTS = {
    "calibration": 225.0,
    "zhang": 148.0,
    "fixed_point": 110.0,
    "initial_directions": 11.0,
    "chessboard": 298.0,
    "relative_positioning": 43.0,
    "tracking": 72.0,
    STUDY_JOB: 115.0,
}
SWEEP_COST = 1000.0


@dataclass(frozen=True)
class _Job:
    """A job of the run: what it runs, the jobs it needs, and its arguments from their data."""

    name: str
    run: Callable[..., dict[str, Any]]
    needs: tuple[str, ...]
    args: Callable[[dict[str, dict[str, Any]]], tuple[Any, ...]]


def critical_order(plan: list[_Job]) -> dict[str, float]:
    """Each job's longest path to the end of the run (its cost and its dependents'), in
    render-times: the priority of list scheduling."""
    level: dict[str, float] = {}
    for job in reversed(_topological(plan)):
        after = [level[j.name] for j in plan if job.name in j.needs]
        level[job.name] = COSTS.get(job.name, SWEEP_COST) + max(after, default=0.0)
    return level


def _topological(plan: list[_Job]) -> list[_Job]:
    order: list[_Job] = []
    placed: set[str] = set()
    for _ in range(len(plan)):  # bounded: one job placed per pass at least
        for job in plan:
            if job.name not in placed and all(n in placed for n in job.needs):
                order.append(job)
                placed.add(job.name)
        if len(order) == len(plan):
            return order
    raise ValueError(
        f"jobs with unmet or circular needs: {sorted({j.name for j in plan} - placed)}"
    )


@contextlib.contextmanager
def _interrupt_deferred() -> Iterator[None]:
    """Ctrl-C waits until the block ends (then KeyboardInterrupt): a worker the pool
    is spawning is never left half-started (it would print a traceback and stay
    unknown to the pool).  Only in the main thread; elsewhere it does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda number, frame: caught.append(number))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught:
        raise KeyboardInterrupt


def _schedule(
    pool: futures.Executor,
    workers: int,
    plan: list[_Job],
    finished: Callable[[str, dict[str, Any] | None, str, float], None],
    skipped: Callable[[str, str], None],
    ran: Callable[[str, dict[str, Any]], None],
) -> str:
    """Run ``plan`` on ``pool``, at most ``workers`` jobs at a time: of the jobs whose
    needs are done, the one with the longest path to the end first (the pool
    would otherwise start them in the order they were queued, whatever frees
    first).  A job whose need failed is skipped.  Returns why it ended."""
    level = critical_order(plan)
    waiting = sorted(plan, key=lambda j: -level[j.name])
    done: dict[str, dict[str, Any]] = {}
    failed: set[str] = set()
    running: dict[futures.Future[dict[str, Any]], tuple[str, float]] = {}
    # Ended jobs are reported after the next jobs started: a report (a figure) must
    # not keep a worker idle.
    ended: list[tuple[str, dict[str, Any] | None, str, float]] = []
    for _ in range(2 * len(plan) + 1):  # each pass starts or ends a job at least
        for job in list(waiting):
            missing = next((n for n in job.needs if n in failed), None)
            if missing is not None:
                waiting.remove(job)
                failed.add(job.name)
                skipped(job.name, missing)
            elif len(running) < workers and all(n in done for n in job.needs):
                waiting.remove(job)
                with _interrupt_deferred():
                    future = pool.submit(job.run, *job.args(done))
                running[future] = (job.name, time.perf_counter())
        for report in ended:
            finished(*report)
        ended.clear()
        if not running:
            return (
                "every job ended"
                if not waiting
                else f"stuck: {[j.name for j in waiting]} wait for jobs that never ran"
            )
        ready, _ = futures.wait(running, return_when=futures.FIRST_COMPLETED)
        for future in ready:
            name, began = running.pop(future)
            try:
                data = future.result()
            except Exception as err:
                failed.add(name)
                error = str(err) if isinstance(err, JobError) else _why(err)
                ended.append((name, None, error, time.perf_counter() - began))
                continue
            ran(name, data)
            done[name] = data
            ended.append((name, data, "", time.perf_counter() - began))
    return "stopped: more passes than jobs allow"


def _why(err: BaseException) -> str:
    text = "".join(traceback.format_exception_only(type(err), err)).strip()
    return text.splitlines()[-1] if text else repr(err)


def main(args: Any) -> int:
    """``headsim reproduce``: exit 0 all ran, 1 an experiment failed, 2 bad input, 130 interrupted."""
    progress = quiet if getattr(args, "quiet", False) else Status("headsim reproduce")
    try:
        state = reproduce(
            args.out,
            fast=args.fast,
            workers=args.workers,
            sweeps=args.sweeps,
            seed=args.seed,
            progress=progress,
        )
    except KeyboardInterrupt:
        print(
            f"\nheadsim: interrupted: the report so far is in {Path(args.out) / 'report.md'}",
            file=sys.stderr,
        )
        return 130
    print(
        f"{state['status']}: {Path(args.out) / 'report.md'}; wall {state['wall_s']:.1f} s = "
        f"{state['wall_over_render']:.0f} x the median 640x480 render ({1e3 * state['render_s']:.1f} ms)"
    )
    return 0 if state["status"] == "ok" else 1
