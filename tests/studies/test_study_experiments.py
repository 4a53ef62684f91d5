"""The study's experiments: the comparison's figures are ratios of RMS errors."""

from __future__ import annotations

from headsim.studies import head_changes
from headsim.studies.methods import METHODS, StudyConfig
from headsim.studies.study_experiments import compare_experiment

CONFIG = StudyConfig.quick()


def test_the_comparison_figures_are_ratios_of_rms_errors(calibrations) -> None:
    experiment = compare_experiment(CONFIG)
    labels = [(c.group, c.label) for c in experiment.conditions]
    assert labels[:2] == [("paper", "as calibrated"), ("paper", "zoom 1.5x")]
    assert experiment.methods == METHODS
    # Two heads only differ in their principal points.
    paper, centred = experiment.base.values()
    assert centred == head_changes.centred(paper)
