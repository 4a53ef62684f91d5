"""The study: stereo against the active method, changes after calibration, sweeps and their files."""

from __future__ import annotations

import csv
import json
import math

import cv2
import numpy as np
import pytest

from headsim.active.principal import zoomed
from headsim.run.results import to_jsonable
from headsim.sim.settings import paper_head
from headsim.studies import study
from headsim.studies.calibrations import CalibrationCache, Calibrations, calibrate_methods
from headsim.studies.head_changes import (
    centred,
    k1_changed,
    principal_shifted,
    with_encoder,
    with_noise,
)
from headsim.studies.methods import METHODS, SWEEP_METHODS, StudyConfig
from headsim.studies.study_experiments import compare_experiment, run_experiment, sweep_experiment
from headsim.studies.study_output import write_experiment
from headsim.studies.target_errors import measure_methods, summarise
from headsim.studies.targets import table_targets

CONFIG = StudyConfig.quick()


@pytest.fixture(scope="module")
def calibrations() -> Calibrations:
    """Every method calibrated once on the paper's head, small (about 5 s)."""
    return calibrate_methods(paper_head(seed=CONFIG.seed), CONFIG)


def test_calibrations_are_close_to_the_truth(calibrations) -> None:
    report = calibrations.report()
    assert report["stereo"]["rms_px"] < 0.2
    assert max(abs(e) for e in report["stereo"]["focal_error_pct"]) < 0.5
    assert np.abs(report["active"]["alpha_e_error_mrad"]).max() < 0.5
    assert np.abs(report["principal_point"]["error_px"]).max() < 0.2
    assert np.abs(report["fixed_point"]["alpha_e_error_mrad"]).max() < 0.5
    json.dumps(to_jsonable(report), allow_nan=False)  # plain JSON


def test_stereo_baseline_error_at_a_known_depth_is_below_a_tenth_of_a_percent(
    calibrations,
) -> None:
    errors = measure_methods(calibrations.settings, calibrations, [[0.03, 0.01, 0.6]], ("stereo",))
    (e,) = errors
    assert e.ok and e.renders == 2
    np.testing.assert_allclose(e.truth_head_m, [0.03, 0.01, 0.6], atol=1e-12)
    assert e.error_pct_depth < 0.25


def test_a_zoom_breaks_stale_stereo_and_the_image_centre_but_not_the_fixed_point(
    calibrations,
) -> None:
    methods = ("stereo", "active_v_known", "active_fixed_point")
    targets = table_targets(3)
    before = measure_methods(calibrations.settings, calibrations, targets, methods)
    after = measure_methods(zoomed(calibrations.settings, 1.5), calibrations, targets, methods)
    s0 = {m: summarise(before, m) for m in methods}
    s1 = {m: summarise(after, m) for m in methods}
    assert all(s.ok == 3 for s in (*s0.values(), *s1.values()))
    assert s0["stereo"].rms_pct_depth < 0.25 and s0["active_v_known"].rms_pct_depth < 0.25
    assert s1["stereo"].rms_mm > 5 * s0["stereo"].rms_mm
    # The paper's off-centre principal points: the image centre's rays turn by mrads.
    assert s1["active_v_known"].rms_pct_depth > 3.0
    assert s1["active_fixed_point"].rms_mm < 1.5 * s0["active_fixed_point"].rms_mm
    assert s1["active_fixed_point"].rms_pct_depth < 0.1


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


def test_the_comparison_figures_are_ratios_of_rms_errors(calibrations) -> None:
    experiment = compare_experiment(CONFIG)
    labels = [(c.group, c.label) for c in experiment.conditions]
    assert labels[:2] == [("paper", "as calibrated"), ("paper", "zoom 1.5x")]
    assert experiment.methods == METHODS
    # Two heads only differ in their principal points.
    paper, centred = experiment.base.values()
    assert centred == centred(paper)


def test_head_changes_move_what_they_say() -> None:
    head = paper_head()
    shifted = principal_shifted(head, 5.0)
    (cx1, cy1), (cx2, cy2) = (c.principal for c in head.cameras)
    assert shifted.cameras[0].principal == (cx1 + 5, cy1 + 5)
    assert shifted.cameras[1].principal == (cx2 - 5, cy2 + 5)
    assert [c.k1 for c in k1_changed(head, 0.1).cameras] == pytest.approx(
        [c.k1 + 0.1 for c in head.cameras]
    )
    assert with_encoder(head, 6400).encoder_resolution_rad == pytest.approx(2 * math.pi / 6400)
    assert all(c.noise_std == 4 for c in with_noise(head, 4).cameras)
    assert all(c.principal == c.image_centre for c in centred(head).cameras)


def test_unknown_names_are_clear_errors(calibrations) -> None:
    with pytest.raises(ValueError, match="unknown sweep 'nope'; allowed: depth, focal"):
        sweep_experiment("nope", CONFIG)
    with pytest.raises(ValueError, match="unknown methods"):
        measure_methods(calibrations.settings, calibrations, [[0, 0, 1]], ("laser",))
    with pytest.raises(SystemExit) as exit_info:
        study.main(["--sweep", "nope", "--out", "unused"])
    assert exit_info.value.code == 2


def test_the_command_runs_a_sweep_with_progress_and_files(tmp_path, capsys) -> None:
    assert study.main(["--sweep", "depth", "--fast", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "calibrating every method on paper" in captured.err
    assert "[2/2] paper: 1.5 (kept)" in captured.err
    assert "== depth" in captured.out and "stereo" in captured.out
    index = json.loads((tmp_path / "results.json").read_text())
    assert set(index["experiments"]) == {"depth"}
    for name in index["experiments"]["depth"]["files"].values():
        assert (tmp_path / name).stat().st_size > 0
