"""The campaigns' catalogue (studies/catalogue.py): the study's experiment file is read
into hooks and refused naming the field; the comparison figures are ratios of RMS errors;
reproduce's experiments run shipped scenarios and each has a cost."""

from __future__ import annotations

import pytest

from headsim.active.principal import zoomed
from headsim.errors import BadInput, ExitCode
from headsim.scenario.loading import scenario_files
from headsim.studies import head_changes
from headsim.studies.catalogue import (
    COSTS,
    REPRODUCE,
    SCENARIO_JOBS,
    STUDY,
    STUDY_JOB,
    SWEEPS,
    TABLES_HEAD,
    JobOutcome,
    ReproduceError,
    compare_experiment,
    read_reproduce_experiments,
    read_study_experiments,
)
from headsim.studies.methods import METHODS, SWEEP_METHODS, StudyConfig
from headsim.studies.reproduce_jobs import JOB_HOOKS
from headsim.studies.sweep_spec import SweepError

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
def test_the_study_file_names_its_hooks_and_choices() -> None:
    assert list(SWEEPS) == ["depth", "focal", "principal", "k1", "noise", "encoder"]
    assert SWEEPS["focal"].change is zoomed and SWEEPS["focal"].modes == ("kept", "redone")
    assert SWEEPS["depth"].targets == "depth" and SWEEPS["k1"].targets == "table"
    assert SWEEPS["principal"].methods == METHODS and SWEEPS["noise"].methods == SWEEP_METHODS
    assert SWEEPS["encoder"].log_x and SWEEPS["depth"].fast_values == (0.4, 1.5)
    assert [c.label for c in STUDY.changes][:1] == ["zoom 1.5x"]
    assert all(c.change in head_changes.HEAD_CHANGES.values() for c in STUDY.changes)


_GOOD_SWEEP = """
[compare]
title = "t"
changes = [{ label = "z", value = 1, change = "zoom" }]
[sweep.s]
parameter = "p"
values = [1, 2.5]
fast_values = [1]
change = "zoom"
modes = ["kept"]
"""


@pytest.mark.fast
@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ('zoom"\nmodes', 'nope"\nmodes'),
            r"sweep\.s\.change: unknown 'nope' \(allowed: zoom, none,",
        ),
        (
            ('["kept"]', '["later"]'),
            r"sweep\.s\.modes: unknown \['later'\] \(allowed: kept, redone\)",
        ),
        (("values = [1, 2.5]", "values = []"), r"sweep\.s\.values: must be numbers, got \[\]"),
        (('parameter = "p"', "parameter = 3"), r"sweep\.s\.parameter: must be str, got 3"),
        (('title = "t"', 'titel = "t"'), r"compare\.title: is missing"),
        (("[{ label", "[3, { label"), r"compare\.changes\[0\]: must be a table, got 3"),
        (
            ("modes = [", "colour = 1\nmodes = ["),
            r"sweep\.s\.colour: unknown key \(allowed: parameter, values,",
        ),
    ],
)
def test_a_bad_study_file_is_refused_naming_the_field(tmp_path, edit, message) -> None:
    path = tmp_path / "study.toml"
    path.write_text(_GOOD_SWEEP)
    good = read_study_experiments(path)
    assert good.sweeps["s"].values == (1.0, 2.5) and good.changes[0].value == 1.0
    path.write_text(_GOOD_SWEEP.replace(*edit))
    with pytest.raises(SweepError, match=f"^{path}: " + message) as refused:
        read_study_experiments(path)
    assert refused.value.exit_code == ExitCode.BAD_INPUT


@pytest.mark.fast
def test_every_experiment_runs_a_shipped_scenario_and_has_a_cost() -> None:
    shipped = {path.stem for path in scenario_files()}
    assert {scenario for scenario, _ in SCENARIO_JOBS.values()} | {TABLES_HEAD} <= shipped
    assert set(SCENARIO_JOBS) | {STUDY_JOB, TABLES_HEAD} <= set(COSTS)
    assert all(cost > 0 for cost in COSTS.values())
    # --fast is a smaller run of every job: the scheduler plans it with its own costs.
    assert all(0 < job.fast_cost <= job.cost for job in REPRODUCE.jobs.values())
    assert [job.cost_of(True) for job in REPRODUCE.jobs.values()] != [
        job.cost_of(False) for job in REPRODUCE.jobs.values()
    ]


@pytest.mark.fast
def test_reproduce_s_file_names_registered_hooks_in_planned_order() -> None:
    assert list(REPRODUCE.jobs)[:3] == ["calibration", "zhang", "fixed_point"]
    assert {job.hook for job in REPRODUCE.jobs.values()} <= set(JOB_HOOKS)
    assert REPRODUCE.jobs[STUDY_JOB].after == ("calibration", "zhang", "fixed_point")
    # The realistic board uses its own calibration, so it reproduces no section itself.
    board = REPRODUCE.jobs["chessboard_realistic"]
    assert board.overrides == {"head.preset": "realistic"} and board.after == ()
    assert list(SCENARIO_JOBS) == [
        "initial_directions",
        "chessboard",
        "relative_positioning",
        "tracking",
    ]
    assert REPRODUCE.sweep_cost > max(COSTS.values())


@pytest.mark.fast
@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            '[job.a]\nhook = "h"\ncost = 1\nfast_cost = 1\nafter = ["b"]',
            r"job\.a\.after: \['b'\] names no earlier job",
        ),
        (
            '[job.a]\nhook = "h"\ncost = "x"\nfast_cost = 1',
            r"job\.a\.cost: must be numbers, got 'x'",
        ),
        ('[job.a]\nhook = "h"\ncost = 1', r"job\.a\.fast_cost: is missing"),
        (
            '[job.a]\nhook = "h"\ncost = 1\nfast_cost = 1\nwhen = 2',
            r"job\.a\.when: unknown key \(allowed: hook,",
        ),
        ("[job.a]\ncost = 1\nfast_cost = 1", r"job\.a\.hook: is missing"),
    ],
)
def test_a_bad_reproduce_file_is_refused_naming_the_field(tmp_path, text, message) -> None:
    path = tmp_path / "reproduce.toml"
    path.write_text('sweep_cost = 10\n[job.b]\nhook = "h"\ncost = 2\nfast_cost = 0.5\n')
    job = read_reproduce_experiments(path).jobs["b"]
    assert (job.cost_of(False), job.cost_of(True)) == (2.0, 0.5)
    path.write_text("sweep_cost = 10\n" + text)
    with pytest.raises(SweepError, match=f"^{path}: " + message):
        read_reproduce_experiments(path)


@pytest.mark.fast
def test_a_reproduce_error_is_bad_input_and_outcomes_do_not_share_their_data() -> None:
    error = ReproduceError("--workers: 0 is not allowed")
    assert isinstance(error, BadInput) and isinstance(error, ValueError)
    assert error.exit_code == ExitCode.BAD_INPUT == 2
    first, second = JobOutcome("a", "ok", 1.0), JobOutcome("b", "ok", 2.0)
    first.data["x"] = 1
    assert second.data == {} and first.error == ""
