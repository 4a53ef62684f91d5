"""Sweep files (TOML): reading and checking one into its jobs (a grid or a seeded random
sample of scenario fields)."""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from headsim.errors import BadInput
from headsim.studies.scenario_jobs import Job


class SweepError(BadInput, ValueError):
    """A bad sweep file: the message names the file, the field and what is allowed."""

    def __init__(self, source: str, path: str, message: str, allowed: str | None = None) -> None:
        text = f"{source}: {path}: {message}" if path else f"{source}: {message}"
        super().__init__(text + (f" (allowed: {allowed})" if allowed else ""))


#: How a sweep's jobs run: one scenario run at a time per process, or in lockstep batches
#: (:mod:`headsim.lockstep.runs`: every target of a batch a head, drawn through one context).
BACKENDS = ("classic", "batch")
#: The most heads one batch holds.
MAX_WORLDS = 4096


@dataclass(frozen=True)
class BatchOptions:
    """A ``[batch]`` table: heads per batch, and the device checked before any job runs
    (lockstep draws every head through one OpenGL context, at each head's own
    ``render`` fidelity)."""

    worlds: int = 32
    device: str = "cpu"


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep file."""

    path: Path
    description: str
    scenario: str
    fast: bool
    fields: tuple[str, ...]
    jobs: tuple[Job, ...]
    backend: str = "classic"
    batch: BatchOptions = BatchOptions()


def _job_id(scenario: str, fast: bool, params: dict[str, Any]) -> str:
    text = json.dumps({"scenario": scenario, "fast": fast, "params": params}, sort_keys=True)
    return hashlib.sha1(text.encode()).hexdigest()[:12]


def _values(source: str, key: str, value: Any) -> list[Any]:
    if not isinstance(value, list) or not value:
        raise SweepError(
            source, f"grid.{key}", f"must be a non-empty list, got {value!r}", "a list of values"
        )
    return value


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and check a sweep file; every job's scenario is validated before anything runs.

    A job whose scenario the reach check refuses (:class:`TargetRefused`: its values put a
    target out of the head's reach) is kept: it fails when it runs, with that reason.
    """
    from headsim.scenario.loading import load_scenario, resolve_path
    from headsim.scenario.tables import ScenarioError, TargetRefused

    path = Path(path)
    source = str(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError as err:
        raise SweepError(source, "", "no such sweep file") from err
    except tomllib.TOMLDecodeError as err:
        raise SweepError(source, "", f"not valid TOML: {err}") from err
    allowed_top = ("description", "scenario", "fast", "backend", "batch", "grid", "random")
    for key in doc:
        if key not in allowed_top:
            raise SweepError(source, key, "unknown key", ", ".join(allowed_top))
    description = doc.get("description")
    if not isinstance(description, str) or not description.strip():
        raise SweepError(source, "description", "missing", "a one-line string")
    scenario = doc.get("scenario")
    if not isinstance(scenario, str):
        raise SweepError(source, "scenario", "missing", "a scenario name or a path to a .toml file")
    candidate = (path.parent / scenario).resolve()
    scenario_path = str(candidate) if candidate.is_file() else scenario
    try:
        scenario_path = str(resolve_path(scenario_path))
    except ScenarioError as err:
        raise SweepError(source, "scenario", str(err)) from err
    fast = doc.get("fast", False)
    if not isinstance(fast, bool):
        raise SweepError(source, "fast", f"must be true or false, got {fast!r}", "true, false")
    backend = doc.get("backend", "classic")
    if backend not in BACKENDS:
        raise SweepError(source, "backend", f"{backend!r} is not a back-end", ", ".join(BACKENDS))
    batch = _batch_options(source, doc.get("batch", {}))
    if "batch" in doc and backend != "batch":
        raise SweepError(source, "batch", 'is read only with backend = "batch"')
    if ("grid" in doc) == ("random" in doc):
        raise SweepError(source, "", "needs exactly one of [grid] and [random]", "[grid], [random]")
    if "grid" in doc:
        grid = doc["grid"]
        if not isinstance(grid, dict) or not grid:
            raise SweepError(source, "grid", "must be a table of field = [values]")
        fields = tuple(grid)
        combos = itertools.product(*(_values(source, k, grid[k]) for k in fields))
        params_list = [dict(zip(fields, combo, strict=True)) for combo in combos]
    else:
        params_list, fields = _random_params(source, doc["random"])
    jobs = []
    for index, params in enumerate(params_list):
        overrides = {k: v for k, v in params.items() if k != "seed"}
        seed = params.get("seed")
        try:
            load_scenario(scenario_path, fast=fast, seed=seed, overrides=overrides)
        except TargetRefused:
            pass  # the file is right: this job's values put a target out of reach (its failure)
        except ScenarioError as err:
            raise SweepError(source, f"job {index} {params}", str(err)) from err
        jobs.append(Job(index, _job_id(scenario_path, fast, params), scenario_path, fast, params))
    return SweepSpec(
        path, description.strip(), scenario_path, fast, fields, tuple(jobs), backend, batch
    )


def _batch_options(source: str, table: Any) -> BatchOptions:
    from headsim.sim.batch import DEVICES

    if not isinstance(table, dict):
        raise SweepError(source, "batch", "must be a table", "worlds, device")
    if "samples_per_pixel" in table:  # Warp's, which the batch back-end no longer uses
        raise SweepError(
            source,
            "batch.samples_per_pixel",
            "is not used: lockstep draws each head at its own fidelity (set the head's "
            "render_supersample in the scenario or the grid instead)",
            "worlds, device",
        )
    for key in table:
        if key not in ("worlds", "device"):
            raise SweepError(source, f"batch.{key}", "unknown key", "worlds, device")

    def whole(key: str, high: int) -> Any:
        value = table[key]
        if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= high:
            raise SweepError(
                source, f"batch.{key}", f"{value!r} is not allowed", f"an integer from 1 to {high}"
            )
        return value

    options = BatchOptions()
    if "worlds" in table:
        options = replace(options, worlds=whole("worlds", MAX_WORLDS))
    if "device" in table:
        if table["device"] not in DEVICES:
            raise SweepError(
                source, "batch.device", f"{table['device']!r} is not a device", ", ".join(DEVICES)
            )
        options = replace(options, device=table["device"])
    return options


def _random_params(source: str, table: Any) -> tuple[list[dict[str, Any]], tuple[str, ...]]:
    if not isinstance(table, dict):
        raise SweepError(source, "random", "must be a table")
    for key in table:
        if key not in ("count", "seed", "fields"):
            raise SweepError(source, f"random.{key}", "unknown key", "count, seed, fields")
    count, seed = table.get("count"), table.get("seed", 0)
    if not isinstance(count, int) or not 1 <= count <= 100_000:
        raise SweepError(
            source, "random.count", f"{count!r} is not allowed", "an integer from 1 to 100000"
        )
    if not isinstance(seed, int) or seed < 0:
        raise SweepError(source, "random.seed", f"{seed!r} is not allowed", "an integer >= 0")
    fields = table.get("fields")
    if not isinstance(fields, dict) or not fields:
        raise SweepError(source, "random.fields", "missing", "a table of field = [low, high]")
    rng = np.random.default_rng(seed)
    columns: dict[str, list[Any]] = {}
    for key, bounds in fields.items():
        ok = (
            isinstance(bounds, list)
            and len(bounds) == 2
            and all(isinstance(b, int | float) and math.isfinite(b) for b in bounds)
            and bounds[0] <= bounds[1]
        )
        if not ok:
            raise SweepError(
                source,
                f"random.fields.{key}",
                f"{bounds!r} is not a range",
                "[low, high] with low <= high",
            )
        if key == "seed":
            columns[key] = [
                int(v) for v in rng.integers(int(bounds[0]), int(bounds[1]) + 1, size=count)
            ]
        else:
            columns[key] = [float(v) for v in rng.uniform(bounds[0], bounds[1], size=count)]
    names = tuple(fields)
    return [{k: columns[k][i] for k in names} for i in range(count)], names
