"""Writing a study experiment: its table, plot and index."""

from __future__ import annotations

import csv
import json

import cv2

from headsim.studies.calibrations import CalibrationCache
from headsim.studies.catalogue import run_experiment, sweep_experiment
from headsim.studies.methods import SWEEP_METHODS, StudyConfig
from headsim.studies.study_output import write_experiment

CONFIG = StudyConfig.quick()


def test_a_sweep_writes_its_table_plot_and_index(calibrations, tmp_path) -> None:
    experiment = sweep_experiment("depth", CONFIG)
    assert [c.value for c in experiment.conditions] == [0.4, 1.5]
    cache = CalibrationCache(CONFIG)
    cache.add(calibrations)
    lines: list[str] = []
    result = run_experiment(experiment, CONFIG, progress=lines.append, cache=cache)
    assert any("[2/2] paper: 1.5 (kept)" in line for line in lines)
    files = write_experiment(result, tmp_path)
    assert {p.name for p in files.values()} == {
        "depth.csv",
        "depth_targets.csv",
        "depth.json",
        "depth.png",
    }
    with open(files["csv"], newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 2 * len(SWEEP_METHODS)
    for row in rows:
        assert row["failed"] == "0"
        assert 0 < float(row["rms_pct_depth"]) < 0.5 or row["method"] == "active_centre"
    with open(files["targets_csv"], newline="") as handle:
        targets = list(csv.DictReader(handle))
    assert len(targets) == 2 * CONFIG.targets_per_depth * len(SWEEP_METHODS)
    assert {float(t["true_z_m"]) for t in targets} == {0.4, 1.5}
    payload = json.loads(files["json"].read_text())
    assert payload["config"]["preset"] == "paper" and len(payload["summary"]) == len(rows)
    image = cv2.imread(str(files["png"]))
    assert image is not None and image.shape[0] > 300 and image.shape[1] > 600
    index = json.loads((tmp_path / "results.json").read_text())
    assert index["experiments"]["depth"]["files"]["png"] == "depth.png"
