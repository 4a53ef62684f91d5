"""What ``headsim reproduce`` runs (studies/reproduce_experiments.py): its experiments exist
and each has a cost."""

from __future__ import annotations

from headsim.errors import BadInput, ExitCode
from headsim.scenario.loading import scenario_files
from headsim.studies.reproduce_experiments import (
    COSTS,
    SCENARIO_JOBS,
    STUDY_JOB,
    TABLES_HEAD,
    JobOutcome,
    ReproduceError,
)


def test_every_experiment_runs_a_shipped_scenario_and_has_a_cost() -> None:
    shipped = {path.stem for path in scenario_files()}
    assert {scenario for scenario, _ in SCENARIO_JOBS.values()} | {TABLES_HEAD} <= shipped
    assert set(SCENARIO_JOBS) | {STUDY_JOB, TABLES_HEAD} <= set(COSTS)
    assert all(cost > 0 for cost in COSTS.values())


def test_a_reproduce_error_is_bad_input_and_outcomes_do_not_share_their_data() -> None:
    error = ReproduceError("--workers: 0 is not allowed")
    assert isinstance(error, BadInput) and isinstance(error, ValueError)
    assert error.exit_code == ExitCode.BAD_INPUT == 2
    first, second = JobOutcome("a", "ok", 1.0), JobOutcome("b", "ok", 2.0)
    first.data["x"] = 1
    assert second.data == {} and first.error == ""
