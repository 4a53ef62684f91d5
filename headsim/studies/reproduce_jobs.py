"""The jobs of ``headsim reproduce``, run in worker processes (module-level, so they pickle):
the head's calibration, Zhang's, the fixed points', the scenarios, Tables V/VI, the sweeps;
registered by the names ``reproduce_experiments.toml`` gives as hooks (:data:`JOB_HOOKS`).
Each takes the job's name, the output directory, ``--fast``, ``--seed`` and the data of the
jobs it comes after."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from headsim.files import to_jsonable, write_json_atomic, write_text_atomic
from headsim.studies.catalogue import FIXED_POINT_TARGETS, REPRODUCE, TABLES_HEAD
from headsim.studies.hooks import registrar
from headsim.studies.jobs import plain_errors
from headsim.studies.scenario_jobs import Job

#: What the jobs import, loaded by each worker as it starts (about 1 s), while the parent
#: makes its render clock.
WORKER_MODULES = (
    "headsim.runs.runner",
    "headsim.runs.serialise",
    "headsim.runs.summary",
    "headsim.scenario.loading",
    "headsim.active.calibration_file",
    "headsim.studies.paper_tables",
    "headsim.studies.catalogue",
    "headsim.studies.study_output",
)

#: A reproduce job: (name, out, fast, seed, the data of the jobs it comes after) -> data.
JobHook = Callable[[str, str, bool, "int | None", dict[str, Any]], dict[str, Any]]
#: The hooks a reproduce experiment file names: name -> job.
JOB_HOOKS: dict[str, JobHook] = {}
#: ``@job_hook("name")``: register a job under the name experiment files use.
job_hook = registrar(JOB_HOOKS)


@job_hook("calibrate")
@plain_errors
def calibrate_job(
    _name: str, out: str, fast: bool, seed: int | None, _after: dict[str, Any]
) -> dict[str, Any]:
    """The head's one Sec. V calibration, written to ``out/head.json``."""
    from headsim.active.calibration_file import head_hash, write_calibration
    from headsim.codec import encode
    from headsim.runs.runner import calibrate_scenario
    from headsim.scenario.loading import load_scenario

    scenario = load_scenario("calibration", fast=fast, seed=seed)
    start = time.perf_counter()
    report = calibrate_scenario(scenario)
    wall = time.perf_counter() - start
    if not report.ok:
        raise RuntimeError(f"calibration failed: {report.status_text}")
    path = write_calibration(
        (Path(out) / "head.json").resolve(), scenario.settings, report, "calibration", scenario.seed
    )
    return {
        "path": str(path),
        "block": encode(report),
        "head_hash": head_hash(scenario.settings),
        "seed": scenario.seed,
        "wall_s": wall,
    }


def _scenario_run(job: Job, directory: Path) -> dict[str, Any]:
    """One scenario run: its results.json and summary.txt written in ``directory``."""
    from headsim.codec import encode
    from headsim.runs.runner import run_scenario
    from headsim.runs.serialise import results_payload
    from headsim.runs.summary import summary_text

    scenario = job.load()
    start = time.perf_counter()
    result = run_scenario(scenario)
    wall = time.perf_counter() - start
    payload = to_jsonable(results_payload(result))
    write_json_atomic(directory / "results.json", payload)
    write_text_atomic(directory / "summary.txt", summary_text(result) + "\n")
    return {
        "results": payload,
        "wall_s": wall,
        "render_counts": encode(result.renders),
        "rendered_frames": result.rendered_frames,
        "points": len(result.records),
    }


@job_hook("scenario")
@plain_errors
def scenario_job(
    name: str, out: str, fast: bool, seed: int | None, after: dict[str, Any]
) -> dict[str, Any]:
    """The file's scenario with its overrides; with head.json when it comes after the
    calibration, else with the scenario's own calibration."""
    spec = REPRODUCE.jobs[name]
    params = dict(spec.overrides)
    if "calibration" in after:
        params["experiment.calibration.from"] = after["calibration"]["path"]
    params["seed"] = seed
    return _scenario_run(Job(0, name, spec.scenario, fast, params), Path(out) / name)


def _study_config(fast: bool, seed: int | None) -> Any:
    from headsim.studies.methods import StudyConfig

    make = StudyConfig.quick if fast else StudyConfig
    return make(seed=seed or 0)


@job_hook("zhang")
@plain_errors
def zhang_job(
    _name: str, _out: str, fast: bool, seed: int | None, _after: dict[str, Any]
) -> dict[str, Any]:
    """Zhang's stereo calibration of the one head, once (it needs no head.json)."""
    from headsim.scenario.loading import load_scenario
    from headsim.studies.paper_tables import zhang_calibration

    scenario = load_scenario(TABLES_HEAD, fast=fast, seed=seed)
    start = time.perf_counter()
    calibration, renders = zhang_calibration(scenario.settings, _study_config(fast, seed))
    return {"calibration": calibration, "renders": renders, "wall_s": time.perf_counter() - start}


@job_hook("fixed_point")
@plain_errors
def fixed_point_job(
    _name: str, _out: str, fast: bool, seed: int | None, _after: dict[str, Any]
) -> dict[str, Any]:
    """The zoom fixed points and the Sec. V calibration on their columns, once (beyond the
    paper: the active method that the focal length's change does not move)."""
    from headsim.scenario.loading import load_scenario
    from headsim.studies.paper_tables import fixed_point_calibration

    scenario = load_scenario(TABLES_HEAD, fast=fast, seed=seed)
    start = time.perf_counter()
    config = _study_config(fast, seed)
    targets = min(config.calibration_targets, FIXED_POINT_TARGETS)
    fixed = fixed_point_calibration(
        scenario.settings, dataclasses.replace(config, calibration_targets=targets)
    )
    return {"fixed": fixed, "targets": targets, "wall_s": time.perf_counter() - start}


@job_hook("tables")
@plain_errors
def tables_job(
    _name: str, out: str, fast: bool, seed: int | None, after: dict[str, Any]
) -> dict[str, Any]:
    """Tables V/VI and the changed focal length with the one calibration and Zhang's."""
    from headsim.active.calibration_file import read_calibration
    from headsim.scenario.loading import load_scenario
    from headsim.studies import paper_tables
    from headsim.studies.study_output import experiment_record, write_experiment

    head, zhang, fixed = after["calibration"]["path"], after["zhang"], after["fixed_point"]
    settings = load_scenario(TABLES_HEAD, fast=fast, seed=seed).settings
    stored = read_calibration(head, settings).knowledge
    calibration = zhang["calibration"]
    result = paper_tables.run_tables(
        settings, calibration, stored, _study_config(fast, seed), fixed["fixed"]
    )
    # The PNG is drawn by the parent, which loads matplotlib while the workers run.
    files = write_experiment(result, Path(out) / "study", figure=False)
    own = result.seconds + zhang["wall_s"] + fixed["wall_s"]
    data = to_jsonable(
        {
            **experiment_record(result, files),
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
                "alpha_e_error_mrad": [1e3 * e for e in fixed["fixed"].alpha_e_error_rad],
            },
            "renders": zhang["renders"]
            + fixed["fixed"].renders
            + sum(e.renders for r in result.results for e in r.errors),
        }
    )
    data["result"] = result  # for the parent to draw the PNG
    return data


@plain_errors
def study_job(
    name: str, out: str, fast: bool, seed: int | None, _after: dict[str, Any]
) -> dict[str, Any]:
    """One of the study's sweeps (``sweep_<name>``, with ``--sweeps``)."""
    from headsim.studies.catalogue import run_experiment, sweep_experiment
    from headsim.studies.study_output import experiment_record, write_experiment

    config = _study_config(fast, seed)
    experiment = sweep_experiment(name.removeprefix("sweep_"), config)
    result = run_experiment(experiment, config)
    files = write_experiment(result, Path(out) / "study")
    return to_jsonable(experiment_record(result, files))
