"""The procedures on real scenes (issue 41, item 5): the one-step fixation and Model 1 on
clicked points of natural_field's room, and the live pursuit of a textured box, each
through the command line (their fast variants) or the runner, with real renders."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from shipped_runs import ShippedRun

from headsim.cli import main
from headsim.live.head import LiveHead
from headsim.procedures.pursuit import PursuitResult
from headsim.runs.runner import run_scenario
from headsim.runs.surface import false_fixation_limit_m
from headsim.scenario.loading import load_scenario, scenario_from_document


@pytest.mark.parametrize("name", ["natural_field_fixation", "natural_field_model1"])
def test_a_room_scenario_counts_every_target_it_asked_for(
    name: str, shipped_fast_run: Callable[[str], ShippedRun]
) -> None:
    run = shipped_fast_run(name)
    results = json.loads((run.directory / "results.json").read_text())
    drawn = results["experiment"]["surface_targets"]
    measurements = results["measurements"]
    assert len(measurements) == drawn["asked"] == 2
    ok = [m for m in measurements if m["status"] == "ok"]
    assert run.code == (0 if len(ok) == len(measurements) else 1), run.out
    for m in measurements:
        # A failure keeps the depth of the start pose, where the target was drawn.
        assert m["depth_m"] == pytest.approx(m["truth_head_m"][2]) and m["depth_m"] > 0.25
        if m["status"] != "ok":
            assert m["failure"]["cause"] and m["fixation"]["landed"] == ["", ""]
            continue
        f = m["fixation"]
        assert all(math.isfinite(v) for v in (*f["error_m"], f["vergence_error_deg"])), f
        assert f["landed"][0] and f["landed"][1]
        assert f["false_fixation"] == (f["error_m"][0] > f["false_fixation_limit_m"])
    assert drawn["false_fixations"] == sum(m["fixation"]["false_fixation"] for m in ok)
    assert "markerless fixations" in run.out


def test_one_step_fixation_lands_both_eyes_on_a_rich_texture_point() -> None:
    # An easy target: a pink-noise poster square to the head 0.9 m away, the only surface
    # within the drawn field's depths, nothing else in the room; the calibrated head.
    doc = {
        "description": "one-step fixation of a point on a poster",
        "seed": 3,
        "head": {"model": "independent_eyes", "preset": "realistic"},
        "cam1": {"noise_std": 1.0},
        "cam2": {"noise_std": 1.0},
        "experiment": {
            "procedure": "fixation",
            "calibration": {"targets": 8, "depth_m": [0.25, 1.2], "position_noise_m": 0.001},
        },
        "scene": {
            "room": {
                "clutter": 0,
                "targets": 2,
                "targets_depth_m": [0.8, 1.0],
                "targets_lateral": 0.05,
                "targets_vertical": 0.05,
                "objects": [
                    {
                        "name": "poster",
                        "shape": "plane",
                        "size_m": [0.3, 0.3, 0.0],
                        "pos_world_m": [0.0, 0.9, 0.21],
                        "pitch_rad": 1.5707963,
                        "texture": "pink",
                        "tile_m": 0.3,
                    }
                ],
            }
        },
    }
    result = run_scenario(scenario_from_document(doc, "poster_fixation"))
    assert len(result.records) == 2
    for record in result.records:
        m, f = record.measurement, record.fixation
        assert m.ok and f is not None, m.status
        depth = float(m.truth_head_m[2])
        assert f.landed == ("poster", "poster")
        # Each eye's final pose: on the clicked point well within the false-fixation limit.
        assert not f.false_fixation and max(f.error_m) < false_fixation_limit_m(depth) / 2
        assert f.vergence_error_deg < 0.1 and f.match_status == "ok"
        assert m.error_pct_of_depth < 1.0


def _pursuit(offset_shift_m: np.ndarray | None = None) -> PursuitResult:
    """pursuit_textured --fast; ``offset_shift_m``: moves the point it is scored against."""
    scenario = load_scenario("pursuit_textured", fast=True)
    with pytest.MonkeyPatch.context() as patch:
        if offset_shift_m is not None:
            real = LiveHead.target_truth

            def shifted(self: LiveHead, time_s: float) -> np.ndarray | None:
                truth = real(self, time_s)
                return None if truth is None else truth + offset_shift_m

            patch.setattr(LiveHead, "target_truth", shifted)
        experiment = run_scenario(scenario).experiment
    assert isinstance(experiment, PursuitResult)
    return experiment


def test_pursuit_keeps_the_textured_box_and_measures_it_from_images_alone() -> None:
    kept = _pursuit()
    figures, frames = kept.figures, kept.per_frame
    assert figures is not None and frames is not None and not kept.failures
    # Every frame of its 0.5 s found the clicked point in both images.
    assert figures.frames == figures.frames_present == 16 and figures.frames_lost == 0
    assert all(frames["found"])
    assert figures.position_rms_pct_of_depth < 1.0 and figures.position_max_m < 0.01
    assert figures.vergence_error_rms_deg < 0.2
    assert kept.pursuit["body"] == "crate"
    # The truth only scores: the point scored against moved 5 cm, the same estimates.
    shifted = _pursuit(np.array([0.05, 0.0, 0.0]))
    assert shifted.per_frame is not None and shifted.figures is not None
    assert shifted.per_frame["estimate_world_m"] == frames["estimate_world_m"]
    assert shifted.figures.position_rms_m > 0.04


def test_the_textured_pursuit_records(tmp_path: Path) -> None:
    # The recording needs the phase (the truth's scene) before the click's first image.
    rrd = tmp_path / "run.rrd"
    argv = ["run", "pursuit_textured", "--fast", "--out", str(tmp_path), "--no-progress"]
    assert main([*argv, "--rrd", str(rrd)]) == 0
    assert rrd.stat().st_size > 100_000
    experiment = json.loads((tmp_path / "results.json").read_text())["experiment"]
    assert (
        experiment["frames_lost"] == 0 and len(experiment["per_frame"]["vergence_error_deg"]) == 16
    )
