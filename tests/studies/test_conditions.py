"""The study's conditions run in this process and through the job pool give the same answers."""

from __future__ import annotations

import numpy as np

from headsim.studies.calibrations import CalibrationCache
from headsim.studies.catalogue import run_experiment, sweep_experiment
from headsim.studies.methods import StudyConfig

CONFIG = StudyConfig.quick()


def test_the_study_sweep_runs_through_the_sweep_pool_with_the_same_answers(calibrations) -> None:
    experiment = sweep_experiment("depth", CONFIG)
    cache = CalibrationCache(CONFIG)
    cache.add(calibrations)
    serial = run_experiment(experiment, CONFIG, cache=cache)
    pooled = run_experiment(experiment, CONFIG, cache=cache, workers=2)
    for a, b in zip(serial.results, pooled.results, strict=True):
        assert a.condition.label == b.condition.label
        for ea, eb in zip(a.errors, b.errors, strict=True):
            np.testing.assert_array_equal(ea.estimate_head_m, eb.estimate_head_m)
