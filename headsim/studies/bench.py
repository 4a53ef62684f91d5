"""Regression benchmarks: a fixed suite, one metrics file, a comparison with a stored baseline.

Metrics are chosen to survive a faster or slower machine: accuracy (errors in
% of depth, mm, rad), effort (renders per point) and speed as ratios (wall
time per point over the time of one render; estimator throughput over a bare
numpy reference on the same arrays).  ``benchmarks/baseline.json`` holds the
reference values and why they were last set; ``benchmarks/tolerances.json``
how far each metric may move, and in which direction is worse.
"""

from __future__ import annotations

import math
import platform
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from headsim.active.events import Detected, PhaseStarted
from headsim.active.measurement import HeadKnowledge
from headsim.active.placement import calibration_layout
from headsim.estimators.throughput import run as estimator_throughput
from headsim.files import write_json_atomic
from headsim.runs.events import MeasurementRecorded, Stamp
from headsim.runs.progress import Progress, Status, quiet
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario, scenario_from_document
from headsim.scenario.spec import Scenario
from headsim.sim.settings import HeadSettings, paper_head, preset
from headsim.sim.simulator import HeadSim, start_views
from headsim.studies import experiments
from headsim.studies.bench_cases import BenchCase, case, listing, of_kind, run_script
from headsim.studies.catalogue import SCENARIO_JOBS
from headsim.studies.checks import Metrics, compare, format_table, load_json
from headsim.studies.hooks import registrar
from headsim.studies.render_clock import RenderClock
from headsim.studies.scenario_jobs import run_row
from headsim.studies.scenario_runs import calibration_run, knowledge_file, preset_of
from headsim.studies.targets import random_targets_head, visible_vertical_range
from headsim.version import __version__


def environment() -> dict[str, str]:
    """What the bench ran on: the versions of headsim, MuJoCo, NumPy and Python, the machine."""
    import mujoco

    return {
        "headsim": __version__,
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
    }


@dataclass(frozen=True)
class Faults:
    """Regressions injected on purpose, to prove the comparison catches them.

    ``mount_sign``: the calibrated initial directions are used with the wrong
    sign (a sign slip in an eye's mount offset).  ``double_renders``: every
    servo observation renders twice (a servo that needs twice the renders).
    """

    mount_sign: bool = False
    double_renders: bool = False


class _PointsWatch:
    """Follows a bench run: every detection's uv (None: not found), px; the wall time from
    the measurement phase's start to its last measurement, s; and with ``double_renders``
    one more render of each detection's camera (the injected fault)."""

    def __init__(self, double_renders: bool = False) -> None:
        self.double_renders = double_renders
        self.seen: list[tuple[float, float] | None] = []
        self.started = self.ended = 0.0
        self._sim: HeadSim | None = None

    def notify(self, event: object, at: Stamp) -> None:
        if isinstance(event, PhaseStarted) and event.name == "measurement":
            self._sim, self.started = event.sim, time.perf_counter()
        elif isinstance(event, Detected):
            self.seen.append(event.uv_px)
            if self.double_renders and self._sim is not None:
                self._sim.render(event.camera)
        elif isinstance(event, MeasurementRecorded):
            self.ended = time.perf_counter()

    @property
    def wall_s(self) -> float:
        return self.ended - self.started


def _points_scenario(
    settings: HeadSettings,
    told: Path | None,
    points_head: np.ndarray,
    windows: bool,
) -> Scenario:
    """Model 2 on each of ``points_head`` (N, 3) m by the preset head ``settings``, told the
    calibration file ``told`` (None: nothing), its servo windowed or not."""
    experiment: dict[str, Any] = {"procedure": "model2", "servo": {"windows": windows}}
    if told is not None:
        experiment["calibration"] = {"from": str(told)}
    doc = {
        "description": "The bench's Model 2 points",
        "seed": settings.seed,
        "head": {"preset": preset_of(settings)},
        "experiment": experiment,
        "scene": {
            "targets": [
                {"name": f"point_{k}", "position_head_m": [float(v) for v in p]}
                for k, p in enumerate(points_head)
            ]
        },
    }
    return scenario_from_document(doc, "bench_points")


def _measure_points(
    settings: HeadSettings,
    knowledge: HeadKnowledge,
    points_head: np.ndarray,
    faults: Faults,
    windows: bool = True,
    passes: int = 1,
) -> tuple[list[Any], float, float, list[Any], float]:
    """Model 2 on each point, run as a scenario; returns the measurements, the median render
    time, s, the pixels rendered for the points in full frames, every detection the servo
    made, and the wall time of the points alone, s (not the simulator's set-up).

    The timed points follow one untimed point in a run of its own: the one-time costs of
    a process (module imports on first use, the pooled renderer's window buffers) are not
    a point's, and timed cold they moved the ratio by +-0.5 run to run.  ``passes`` > 1
    runs the points again (their answers unused) and keeps the shortest wall time: a busy
    machine only ever adds time.  Renders are timed on a simulator of the same head
    before and after the points."""
    with tempfile.TemporaryDirectory() as folder:
        told = None
        if knowledge != HeadKnowledge():
            told = knowledge_file(Path(folder) / "told.json", settings, knowledge)
        run_scenario(_points_scenario(settings, told, points_head[:1], windows))
        clock = RenderClock(settings)
        try:
            render_s = clock.sample(10)
            watches, results = [], []
            for _ in range(passes):
                watch = _PointsWatch(faults.double_renders)
                scenario = _points_scenario(settings, told, points_head, windows)
                results.append(run_scenario(scenario, [watch]))
                watches.append(watch)
            # Timed again after the points: the machine's load moves while they run.
            render_s = (render_s + clock.sample(10)) / 2
        finally:
            clock.close()
    first = results[0]
    measured = [r.measurement for r in first.records]
    frames = first.rendered_frames["experiment"]
    return measured, render_s, frames, watches[0].seen, min(w.wall_s for w in watches)


#: The suite's parts, in the order they run: the regression cases of
#: ``bench_cases.toml``; ``suite(parts=...)`` runs a subset (tests and ``headsim bench
#: --case`` do).
PARTS = tuple(c.name for c in of_kind("regress"))

Part = Callable[[int, Faults, Progress], Metrics]
#: Each part's function, by its case's name (:func:`part`).
PART_RUNS: dict[str, Part] = {}
#: ``@part("name")``: register the function that runs the regression case ``name``.
part = registrar(PART_RUNS)


def suite(
    seed: int = 0,
    faults: Faults | None = None,
    progress: Progress = quiet,
    parts: tuple[str, ...] = PARTS,
) -> Metrics:
    """Run the fixed suite; metrics by name (see ``benchmarks/tolerances.json``)."""
    unknown = set(parts) - set(PARTS)
    if unknown:
        raise ValueError(f"unknown bench parts {sorted(unknown)}; allowed: {', '.join(PARTS)}")
    faults = faults or Faults()
    metrics: Metrics = {}
    for name in PARTS:
        if name in parts:
            metrics.update(PART_RUNS[name](seed, faults, progress))
    return metrics


@part("scenarios")
def _scenarios_part(seed: int, faults: Faults, progress: Progress) -> Metrics:
    metrics: Metrics = {}
    for name in PAPER_SCENARIOS:
        progress(f"scenario {name} (fast)")
        metrics.update(scenario_metrics(name))
    return metrics


@part("speed")
def _speed_part(seed: int, faults: Faults, progress: Progress) -> Metrics:
    progress("estimator throughput")
    speed = estimator_throughput(200_000, repeats=3, seed=seed)
    progress("quick start, full size")
    return {
        "speed.model2_over_numpy": speed["model2_over_numpy_eq4_11"],
        "speed.quickstart_over_render": _quickstart_over_render(),
    }


@part("ideal")
def _ideal_part(seed: int, faults: Faults, progress: Progress) -> Metrics:
    rng = np.random.default_rng(seed)
    metrics: Metrics = {}
    progress("ideal cameras, Model 2")
    points = np.concatenate(
        [
            random_targets_head(rng, 4, band, vertical=(-0.15, 0.15))
            for band in experiments.DEPTH_BANDS_M
        ]
    )
    ideal, render_s, frames, seen, wall = _measure_points(
        HeadSettings(), HeadKnowledge(), points, faults, passes=2
    )
    wall /= len(points)
    # The same points with full frames only: windows must change no answer.
    plain, _, _, plain_seen, _ = _measure_points(
        HeadSettings(), HeadKnowledge(), points, faults, windows=False
    )
    fig = experiments.error_figures(ideal)
    metrics["ideal.model2.rms_3d_pct_depth"] = fig["rms_3d_pct_depth"]
    metrics["ideal.model2.failed"] = float(fig["failed"])
    metrics["ideal.model2.renders_per_point"] = float(np.mean([m.renders for m in ideal[1:]]))
    metrics["ideal.model2.servo_residual_px_mean"] = float(
        np.mean([abs(r) for m in ideal if m.ok for r in m.servo_residual_px])
    )
    metrics["speed.wall_per_point_over_render"] = wall / render_s
    metrics["ideal.model2.rendered_frames_per_point"] = frames / len(points)
    metrics["windows.max_estimate_change_m"] = max(
        (
            float(np.max(np.abs(a.estimate_head_m - b.estimate_head_m)))
            for a, b in zip(ideal, plain, strict=True)
            if a.ok and b.ok
        ),
        default=math.inf,
    )
    same_sequence = len(seen) == len(plain_seen) and all(
        (a is None) == (b is None) for a, b in zip(seen, plain_seen, strict=True)
    )
    metrics["windows.max_detection_change_px"] = (
        max(
            (
                float(np.max(np.abs(np.subtract(a, b))))
                for a, b in zip(seen, plain_seen, strict=True)
                if a is not None and b is not None
            ),
            default=0.0,
        )
        if same_sequence
        else math.inf
    )
    return metrics


def _quickstart_over_render() -> float:
    """Wall time of the quick start scenario at full size over one 640x480 render,
    the render timed just before and just after it."""
    scenario = load_scenario("quickstart")
    clock = RenderClock()
    try:
        before = clock.sample(10)
        start = time.perf_counter()
        run_scenario(scenario)
        wall = time.perf_counter() - start
        after = clock.sample(10)
    finally:
        clock.close()
    return wall / ((before + after) / 2)


@part("paper")
def _paper_part(seed: int, faults: Faults, progress: Progress) -> Metrics:
    rng = np.random.default_rng(seed + 1)
    metrics: Metrics = {}
    progress("paper's cameras: Sec. V calibration")
    settings = paper_head()
    knowledge, report = calibration_run(
        settings, calibration_layout(start_views(settings), rng, 30)
    )
    if faults.mount_sign:
        knowledge = HeadKnowledge(
            alpha_e=(-knowledge.alpha_e[0], knowledge.alpha_e[1]),
            v0=knowledge.v0,
            kx_over_ky=knowledge.kx_over_ky,
        )
    assert report.alpha_e_error_rad is not None  # calibration_run raises if it failed
    metrics["paper.calibration.max_error_rad"] = float(np.abs(report.alpha_e_error_rad).max())

    progress("paper's cameras: Model 2 near the centre row")
    low, high = visible_vertical_range(settings)
    near = np.concatenate(
        [
            random_targets_head(rng, 3, band, vertical=(max(low, -0.05), min(high, 0.03)))
            for band in experiments.DEPTH_BANDS_M
        ]
    )
    paper, _, _, _, _ = _measure_points(settings, knowledge, near, faults)
    fig = experiments.error_figures(paper)
    x, y, z = fig.get("rms_pct_depth_xyz", [math.nan] * 3)
    metrics["paper.model2.x_rms_pct_depth"] = x
    metrics["paper.model2.y_rms_pct_depth"] = y
    metrics["paper.model2.z_rms_pct_depth"] = z
    metrics["paper.model2.failed"] = float(fig["failed"])

    progress("chessboard")
    board = experiments.chessboard_accuracy(settings, knowledge, corners=[18, 19, 20, 26, 27, 28])[
        "extended calibration"
    ]
    metrics["chessboard.width_error_mm"] = (
        abs(board["width_mean_mm"] - 30.0) if board["width_mean_mm"] else math.inf
    )
    metrics["chessboard.height_error_mm"] = (
        abs(board["height_mean_mm"] - 30.0) if board["height_mean_mm"] else math.inf
    )
    metrics["chessboard.corners_missed"] = float(board["corners"] - board["corners_measured"])
    metrics["chessboard.width_std_mm"] = board["width_std_mm"] or math.inf
    metrics["chessboard.height_std_mm"] = board["height_std_mm"] or math.inf

    progress("relative positioning")
    # Over every object placed; the subset more than 2 px from a boundary beside it.
    for label, head in (("areas", None), ("areas.paper", settings)):
        if head is not None:
            progress("relative positioning, the paper's cameras")
        areas = experiments.relative_areas(rng, layouts=2, settings=head)
        metrics[f"{label}.correct_pct"] = areas["correct_pct"]
        metrics[f"{label}.outside_margin_correct_pct"] = areas["outside_margin_correct_pct"] or 0.0
        metrics[f"{label}.not_seen"] = float(areas["not_seen_in_all_four_images"])
    return metrics


@part("realistic")
def _realistic_part(seed: int, faults: Faults, progress: Progress) -> Metrics:
    """The realistic preset over the whole shared field after the extended calibration."""
    rng = np.random.default_rng(seed + 2)
    metrics: Metrics = {}
    progress("realistic head: extended calibration (30 balls, 1 mm tape)")
    settings = preset("realistic")
    knowledge, report = calibration_run(
        settings,
        calibration_layout(start_views(settings), rng, 30, depth_range_m=(0.25, 1.5)),
        position_noise_m=0.001,
        lines_of_sight=True,
    )
    if faults.mount_sign:
        knowledge = replace(knowledge, alpha_e=(-knowledge.alpha_e[0], knowledge.alpha_e[1]))
    lines = report.lines_of_sight
    metrics["realistic.calibration.effective_baseline_error_mm"] = (
        abs(1e3 * (lines.effective_baseline_m - lines.effective_baseline_truth_m))
        if lines
        else math.inf
    )
    progress("realistic head: Model 2 over the whole field")
    points = np.concatenate(
        [
            random_targets_head(rng, 4, band, lateral=0.15, vertical=(-0.1, 0.1))
            for band in experiments.DEPTH_BANDS_M
        ]
    )
    measured, *_ = _measure_points(settings, knowledge, points, faults)
    fig = experiments.error_figures(measured)
    near = experiments.error_figures([m for m in measured if m.depth_m < 0.6])
    metrics["realistic.model2.rms_3d_pct_depth"] = fig.get("rms_3d_pct_depth", math.inf)
    metrics["realistic.model2.near_rms_3d_pct_depth"] = near.get("rms_3d_pct_depth", math.inf)
    metrics["realistic.model2.failed"] = float(fig["failed"])
    metrics["realistic.model2.renders_per_point"] = float(
        np.mean([m.renders for m in measured[1:]])
    )
    return metrics


#: The paper scenarios whose fast variants the suite runs: those ``headsim reproduce`` runs.
PAPER_SCENARIOS = tuple(scenario for scenario, _ in SCENARIO_JOBS.values())


def scenario_metrics(name: str) -> Metrics:
    """Run a scenario's fast variant: failures, RMS error (% of depth) and renders."""
    scenario = load_scenario(name, fast=True)
    row = run_row(run_scenario(scenario))
    rms = row["rms_error_pct_depth"]
    metrics = {
        f"scenario.{name}.failures": float(row["failures"]),
        f"scenario.{name}.rms_error_pct_depth": math.inf if rms is None else rms,
        # Per fixation, so that +0.5 renders per point is one tolerance everywhere.
        f"scenario.{name}.renders_per_point": float(row["renders"]) / max(scenario.fixations, 1),
    }
    if row["calibration_max_error_rad"] is not None:
        metrics[f"scenario.{name}.calibration_max_error_rad"] = row["calibration_max_error_rad"]
    return metrics


def selected_cases(args: Any) -> tuple[BenchCase, ...]:
    """The cases ``headsim bench`` runs: ``--case`` names, ``--all``'s, or the regression suite."""
    names = getattr(args, "case", None) or []
    if names:
        return tuple(case(name) for name in names)
    if getattr(args, "all", False):
        return of_kind("regress", "figures")
    return of_kind("regress")


def main(args: Any) -> int:
    """``headsim bench``: list the cases, or run the chosen ones: the regression cases
    compared with the baseline (maybe updating it), then each figures case's script."""
    if getattr(args, "list", False):
        print("\n".join(listing()))
        return 0
    try:
        chosen = selected_cases(args)
    except KeyError as err:
        print(f"headsim bench: {err.args[0]}", file=sys.stderr)
        return 2
    parts = tuple(c.name for c in chosen if c.kind == "regress")
    scripts = [c for c in chosen if c.kind != "regress"]
    script_args = list(getattr(args, "script_args", None) or [])
    if script_args and len(scripts) != 1:
        print(
            "headsim bench: arguments after -- go to one figures case (--case NAME -- ARGS)",
            file=sys.stderr,
        )
        return 2
    if args.update_baseline and parts != PARTS:
        print("headsim bench: --update-baseline needs the whole regression suite", file=sys.stderr)
        return 2
    status = _regress(args, parts) if parts else 0
    for script in scripts:
        status = max(status, run_script(script, script_args))
    return status


def _regress(args: Any, parts: tuple[str, ...]) -> int:
    """The regression cases ``parts``: run, compare, print, maybe update the baseline."""
    silent = getattr(args, "quiet", False)
    start = time.perf_counter()
    status = None if silent else Status("headsim bench", transient=True)
    metrics = suite(seed=args.seed, progress=quiet if status is None else status, parts=parts)
    wall = time.perf_counter() - start
    if status is not None:
        status.close()
    baseline_path = Path(args.baseline)
    stored = load_json(baseline_path)
    verdicts = compare(metrics, stored.get("metrics", {}), load_json(Path(args.tolerances)))
    print(format_table(verdicts))
    print(f"suite wall time {wall:.0f} s")
    if args.json:
        write_json_atomic(
            args.json, {"metrics": metrics, "wall_s": wall, "environment": environment()}
        )
    if args.update_baseline:
        if not args.reason:
            print(
                "headsim bench: --update-baseline needs --reason 'why the figures changed'",
                file=sys.stderr,
            )
            return 2
        history = stored.get("history", [])
        history.append({"reason": args.reason, "environment": environment()})
        write_json_atomic(
            baseline_path, {"metrics": metrics, "seed": args.seed, "history": history}
        )
        print(f"baseline written to {baseline_path}")
        return 0
    regressions = [v for v in verdicts if v.regressed]
    if regressions:
        print(f"{len(regressions)} metric(s) regressed: {', '.join(v.metric for v in regressions)}")
        return 1
    return 0
