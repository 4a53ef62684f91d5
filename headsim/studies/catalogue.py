"""The campaigns' one catalogue of experiments: the study's (the Tables V/VI comparison and
the sweeps, described in ``study_experiments.toml`` and made into conditions here, running
one, the comparison's done-when ratios) and what ``headsim reproduce`` runs (its jobs,
described in ``reproduce_experiments.toml``: their hooks, order and cost in render-times;
Tables V/VI's scope and an experiment's outcome).  The bench's paper scenarios
are reproduce's (:data:`SCENARIO_JOBS`)."""

from __future__ import annotations

import time
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from headsim.errors import BadInput
from headsim.runs.progress import Progress, quiet
from headsim.sim.forward import effective_directions
from headsim.sim.settings import HeadSettings, preset
from headsim.studies.calibrations import CalibrationCache, Calibrations
from headsim.studies.conditions import Condition, ConditionResult, run_conditions
from headsim.studies.head_changes import (
    HEAD_CHANGES,
    HeadChange,
    centred,
)
from headsim.studies.methods import METHODS, SWEEP_METHODS, StudyConfig
from headsim.studies.sweep_spec import SweepError
from headsim.studies.target_errors import Summary
from headsim.studies.targets import depth_targets, table_targets


@dataclass(frozen=True)
class Experiment:
    """A named set of conditions and how to plot them.

    ``kind``: "compare" (bars per condition) or "sweep" (curves against
    ``value``); ``parameter``: the sweep's x axis label; ``methods``: those
    measured; ``log_x``: plot x on a log scale.
    """

    name: str
    title: str
    kind: str
    parameter: str
    base: dict[str, HeadSettings]
    conditions: tuple[Condition, ...]
    methods: tuple[str, ...] = SWEEP_METHODS
    log_x: bool = False


@dataclass(frozen=True)
class Sweep:
    """One sweep: values, how each changes the head, the calibration modes, the targets.

    ``change(head, value)``: the head at that value; ``modes``: "kept" (calibrated on the
    preset, changed after) and/or "redone"; ``targets``: "table" or "depth".
    """

    name: str
    parameter: str
    values: tuple[float, ...]
    fast_values: tuple[float, ...]
    change: HeadChange
    modes: tuple[str, ...]
    log_x: bool = False
    targets: str = "table"
    methods: tuple[str, ...] = SWEEP_METHODS


@dataclass(frozen=True)
class Change:
    """One change after calibration of the comparison: its label, x value and hook."""

    label: str
    value: float
    change: HeadChange


@dataclass(frozen=True)
class StudyExperiments:
    """A checked study experiment file: the comparison's title and changes, the sweeps."""

    compare_title: str
    changes: tuple[Change, ...]
    sweeps: dict[str, Sweep]


#: The study's experiments, as a file.
STUDY_FILE = Path(__file__).with_name("study_experiments.toml")
_SWEEP_KEYS = ("parameter", "values", "fast_values", "change", "modes", "log_x", "targets")
_SWEEP_KEYS_ALL = (*_SWEEP_KEYS, "methods")
_CHOICES = {"modes": ("kept", "redone"), "targets": ("table", "depth"), "methods": ("sweep", "all")}


def _table(source: str, where: str, table: Any, keys: Sequence[str]) -> dict[str, Any]:
    """``table`` if it is a TOML table of only ``keys``."""
    if not isinstance(table, dict):
        raise SweepError(source, where, f"must be a table, got {table!r}")
    unknown = set(table) - set(keys)
    if unknown:
        raise SweepError(source, f"{where}.{min(unknown)}", "unknown key", ", ".join(keys))
    return table


def _take(
    source: str, where: str, table: dict[str, Any], key: str, kind: type, default: Any = None
) -> Any:
    """``table[key]`` (or ``default``): a ``kind`` or a non-empty list of them (for a list
    ``kind``, the list itself), one of the allowed names where the key has a choice."""
    value = table.get(key, default)
    if value is None:
        raise SweepError(source, f"{where}.{key}", "is missing")
    items = value if isinstance(value, list) and kind is not list else [value]
    if not items or not all(isinstance(v, kind) for v in items):
        raise SweepError(source, f"{where}.{key}", f"must be {kind.__name__}, got {value!r}")
    allowed = HEAD_CHANGES if key == "change" else _CHOICES.get(key)
    if allowed is not None and not set(items) <= set(allowed):
        raise SweepError(source, f"{where}.{key}", f"unknown {value!r}", ", ".join(allowed))
    return value


def _floats(source: str, where: str, table: dict[str, Any], key: str) -> tuple[float, ...]:
    """``table[key]``: a number or a non-empty list of numbers, as floats."""
    if key not in table:
        raise SweepError(source, f"{where}.{key}", "is missing")
    value = table[key]
    items: list[Any] = value if isinstance(value, list) else [value]
    if not items or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in items):
        raise SweepError(source, f"{where}.{key}", f"must be numbers, got {value!r}")
    return tuple(float(v) for v in items)


def read_study_experiments(path: Path = STUDY_FILE) -> StudyExperiments:
    """Read and check a study experiment file (:class:`SweepError` naming the field)."""
    source = str(path)
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    compare = data.get("compare", {})
    changes = []
    for i, entry in enumerate(_take(source, "compare", compare, "changes", list)):
        where = f"compare.changes[{i}]"
        entry = _table(source, where, entry, ("label", "value", "change"))
        change = HEAD_CHANGES[_take(source, where, entry, "change", str)]
        value = _floats(source, where, entry, "value")[0]
        changes.append(Change(_take(source, where, entry, "label", str), value, change))
    sweeps = {}
    for name, table in data.get("sweep", {}).items():
        where = f"sweep.{name}"
        table = _table(source, where, table, _SWEEP_KEYS_ALL)
        methods = _take(source, where, table, "methods", str, "sweep")
        sweeps[name] = Sweep(
            name=name,
            parameter=_take(source, where, table, "parameter", str),
            values=_floats(source, where, table, "values"),
            fast_values=_floats(source, where, table, "fast_values"),
            change=HEAD_CHANGES[_take(source, where, table, "change", str)],
            modes=tuple(_take(source, where, table, "modes", str)),
            log_x=_take(source, where, table, "log_x", bool, False),
            targets=_take(source, where, table, "targets", str, "table"),
            methods=METHODS if methods == "all" else SWEEP_METHODS,
        )
    title = _take(source, "compare", compare, "title", str)
    return StudyExperiments(title, tuple(changes), sweeps)


STUDY = read_study_experiments()
SWEEPS: dict[str, Sweep] = STUDY.sweeps


def compare_experiment(config: StudyConfig) -> Experiment:
    """Tables V/VI and the changes after calibration, on the preset and on it with centred principal points."""
    head = preset(config.preset, seed=config.seed)
    targets = table_targets(config.table_targets)
    base = {config.preset: head, f"{config.preset} with centred principal points": centred(head)}
    changes = STUDY.changes[:1] if config.fast else STUDY.changes
    conditions = []
    for group, settings in base.items():
        conditions.append(Condition(group, "as calibrated", 0.0, settings, "kept", targets))
        for c in changes:
            conditions.append(
                Condition(group, c.label, c.value, c.change(settings, c.value), "kept", targets)
            )
    return Experiment(
        name="compare",
        title=STUDY.compare_title,
        kind="compare",
        parameter="condition",
        base=base,
        conditions=tuple(conditions),
        methods=METHODS,
    )


def sweep_experiment(name: str, config: StudyConfig) -> Experiment:
    """The conditions of sweep ``name`` (:data:`SWEEPS`) on the preset's head."""
    if name not in SWEEPS:
        raise ValueError(f"unknown sweep {name!r}; allowed: {', '.join(SWEEPS)}")
    sweep = SWEEPS[name]
    head = preset(config.preset, seed=config.seed)
    values = sweep.fast_values if config.fast else sweep.values
    rng = np.random.default_rng(config.seed + 10)
    conditions = []
    for value in values:
        if sweep.targets == "depth":
            targets = depth_targets(head, value, config.targets_per_depth, rng)
        else:
            targets = table_targets(config.table_targets)
        changed = sweep.change(head, value)
        for mode in sweep.modes:
            conditions.append(Condition(config.preset, f"{value:g}", value, changed, mode, targets))
    return Experiment(
        name=name,
        title=f"error against {sweep.parameter}",
        kind="sweep",
        parameter=sweep.parameter,
        base={config.preset: head},
        conditions=tuple(conditions),
        methods=sweep.methods,
        log_x=sweep.log_x,
    )


@dataclass(frozen=True)
class ExperimentResult:
    experiment: Experiment
    config: StudyConfig
    results: tuple[ConditionResult, ...]
    calibrations: tuple[Calibrations, ...]
    seconds: float

    def summary(self, group: str, label: str, calibration: str, method: str) -> Summary:
        """The summary of one method in one condition."""
        for r in self.results:
            c = r.condition
            if (c.group, c.label, c.calibration) == (group, label, calibration):
                return r.summary(method)
        raise KeyError((group, label, calibration))


def run_experiment(
    experiment: Experiment,
    config: StudyConfig,
    methods: Sequence[str] | None = None,
    progress: Progress = quiet,
    cache: CalibrationCache | None = None,
    workers: int = 1,
    scheduler: str | None = None,
) -> ExperimentResult:
    """Run every condition of ``experiment`` with ``methods`` (default: the experiment's).

    ``workers``/``scheduler``: as :func:`run_conditions`.
    """
    methods = experiment.methods if methods is None else tuple(methods)
    start = time.perf_counter()
    progress(f"== {experiment.name}: {experiment.title} ({len(experiment.conditions)} conditions)")
    cache = cache or CalibrationCache(config, progress)
    results = run_conditions(
        experiment.base, experiment.conditions, cache, methods, progress, workers, scheduler
    )
    used = {
        (experiment.base[c.group] if c.calibration == "kept" else c.head)
        for c in experiment.conditions
    }
    calibrations = tuple(c for c in cache.calibrations if c.settings in used)
    return ExperimentResult(
        experiment, config, tuple(results), calibrations, time.perf_counter() - start
    )


def compare_figures(result: ExperimentResult) -> dict[str, Any]:
    """The done-when ratios of the comparison (RMS of the 3-D error, mm)."""
    exp = result.experiment
    groups = list(exp.base)
    paper = groups[0]
    figures: dict[str, Any] = {}

    def rms(group: str, label: str, method: str) -> float:
        return result.summary(group, label, "kept", method).rms_mm

    methods = [s.method for s in result.results[0].summaries]
    stereo_rms = rms(paper, "as calibrated", "stereo")
    figures["tables_v_vi"] = {
        "stereo_rms_mm": stereo_rms,
        **{f"{m}_over_stereo": rms(paper, "as calibrated", m) / stereo_rms for m in methods[1:]},
    }
    # How far each change turned the image centre's rays (the plain method's offsets).
    turns = {}
    for c in exp.conditions:
        before, after = (effective_directions(h) for h in (exp.base[c.group], c.head))
        turns[f"{c.group}: {c.label}"] = [1e3 * (a - b) for a, b in zip(after, before, strict=True)]
    figures["image_centre_ray_turn_mrad"] = turns
    labels = {c.label for c in exp.conditions}
    if "zoom 1.5x" in labels:
        # The second group (if any) is the paper's head with centred principal points.
        keys = {paper: "zoom_1_5_paper", **{g: "zoom_1_5_centred" for g in groups[1:2]}}
        for group, key in keys.items():
            figures[key] = {
                f"{m}_after_over_before": rms(group, "zoom 1.5x", m)
                / rms(group, "as calibrated", m)
                for m in methods
            }
    return figures


# -- headsim reproduce ---------------------------------------------------------------


@dataclass(frozen=True)
class ReproduceJob:
    """One job of ``headsim reproduce`` as its file describes it: the hook that runs it, the
    jobs it comes after, its cost in render-times in the full and the ``--fast`` run and, for
    a scenario job, the scenario, its overrides and what it reproduces."""

    name: str
    hook: str
    after: tuple[str, ...]
    cost: float
    fast_cost: float
    scenario: str = ""
    overrides: dict[str, Any] = field(default_factory=dict)
    reproduces: str = ""

    def cost_of(self, fast: bool) -> float:
        """Its cost in the run asked for (render-times)."""
        return self.fast_cost if fast else self.cost


@dataclass(frozen=True)
class ReproduceExperiments:
    """A checked reproduce experiment file: its jobs in planned order, a sweep's cost."""

    jobs: dict[str, ReproduceJob]
    sweep_cost: float


#: Reproduce's experiments, as a file.
REPRODUCE_FILE = Path(__file__).with_name("reproduce_experiments.toml")
_JOB_KEYS = ("hook", "after", "cost", "fast_cost", "scenario", "overrides", "reproduces")


def read_reproduce_experiments(path: Path = REPRODUCE_FILE) -> ReproduceExperiments:
    """Read and check a reproduce experiment file (:class:`SweepError` naming the field); a
    job comes after jobs planned before it."""
    source = str(path)
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    jobs: dict[str, ReproduceJob] = {}
    for name, table in data.get("job", {}).items():
        where = f"job.{name}"
        table = _table(source, where, table, _JOB_KEYS)
        after = tuple(table.get("after", ()))
        if not set(after) <= set(jobs):
            raise SweepError(
                source, f"{where}.after", f"{list(after)!r} names no earlier job", ", ".join(jobs)
            )
        scenario = _take(source, where, table, "scenario", str, "")
        overrides = _take(source, where, table, "overrides", dict, {})
        jobs[name] = ReproduceJob(
            name=name,
            hook=_take(source, where, table, "hook", str),
            after=after,
            cost=_floats(source, where, table, "cost")[0],
            fast_cost=_floats(source, where, table, "fast_cost")[0],
            scenario=scenario,
            overrides=overrides,
            reproduces=_take(source, where, table, "reproduces", str, ""),
        )
    return ReproduceExperiments(jobs, _floats(source, "", data, "sweep_cost")[0])


REPRODUCE = read_reproduce_experiments()
#: The scenario jobs that reproduce a part of the paper: name -> (scenario, what).
SCENARIO_JOBS = {
    name: (job.scenario, job.reproduces) for name, job in REPRODUCE.jobs.items() if job.reproduces
}
STUDY_JOB = "tables_v_vi"
#: What the Tables V/VI experiment measures here, and what it leaves to the study.
TABLES_SCOPE = (
    "Measured on this head with `head.json` (the image-centre active methods), one Zhang "
    "calibration (stereo) and one zoom fixed-point calibration (the fixed-point methods, "
    "beyond the paper, fewer ball positions than head.json): the six target positions, as calibrated and with the focal length "
    "x1.5. The three image-centre methods servo once and are computed from the same images. "
    "Smaller than `headsim study --experiment compare`, which also measures a "
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
#: The job that measures the board on the realistic preset, beside the paper preset's.
REALISTIC_BOARD_JOB = "chessboard_realistic"


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


#: What each job costs, in render-times (the file's ``cost``).
COSTS = {name: job.cost for name, job in REPRODUCE.jobs.items()}
SWEEP_COST = REPRODUCE.sweep_cost
