"""The campaigns' catalogue (studies/catalogue.py): the study's comparison figures are
ratios of RMS errors; reproduce's experiments run shipped scenarios and each has a cost."""

from __future__ import annotations

import pytest

from headsim.errors import BadInput, ExitCode
from headsim.scenario.loading import scenario_files
from headsim.studies import head_changes
from headsim.studies.catalogue import (
    COSTS,
    SCENARIO_JOBS,
    STUDY_JOB,
    TABLES_HEAD,
    JobOutcome,
    ReproduceError,
    compare_experiment,
)
from headsim.studies.methods import METHODS, StudyConfig

CONFIG = StudyConfig.quick()


def test_the_comparison_figures_are_ratios_of_rms_errors(calibrations) -> None:
    experiment = compare_experiment(CONFIG)
    labels = [(c.group, c.label) for c in experiment.conditions]
    assert labels[:2] == [("paper", "as calibrated"), ("paper", "zoom 1.5x")]
    assert experiment.methods == METHODS
    # Two heads only differ in their principal points.
    paper, centred = experiment.base.values()
    assert centred == head_changes.centred(paper)


@pytest.mark.fast
def test_every_experiment_runs_a_shipped_scenario_and_has_a_cost() -> None:
    shipped = {path.stem for path in scenario_files()}
    assert {scenario for scenario, _ in SCENARIO_JOBS.values()} | {TABLES_HEAD} <= shipped
    assert set(SCENARIO_JOBS) | {STUDY_JOB, TABLES_HEAD} <= set(COSTS)
    assert all(cost > 0 for cost in COSTS.values())


@pytest.mark.fast
def test_a_reproduce_error_is_bad_input_and_outcomes_do_not_share_their_data() -> None:
    error = ReproduceError("--workers: 0 is not allowed")
    assert isinstance(error, BadInput) and isinstance(error, ValueError)
    assert error.exit_code == ExitCode.BAD_INPUT == 2
    first, second = JobOutcome("a", "ok", 1.0), JobOutcome("b", "ok", 2.0)
    first.data["x"] = 1
    assert second.data == {} and first.error == ""
