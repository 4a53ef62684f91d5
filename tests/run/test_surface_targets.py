"""Markerless targets through the runner: the false-fixation rule on exact synthetic
landings, the scenario keys, and natural_field --fast through the real command line
(its targets measured from clicks, the landing truth in results.json)."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from headsim.cli import main
from headsim.runs.landing import Landing
from headsim.runs.outcomes import FALSE_FIXATION_MIN_M
from headsim.runs.runner import run_scenario
from headsim.runs.surface import Look, false_fixation_limit_m, score_fixation
from headsim.scenario.loading import scenario_from_document
from headsim.scenario.surface_targets import Click
from headsim.scenario.tables import ScenarioError
from headsim.vision.correspondence import Match, MatchStatus

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
TARGET = np.array([0.0, 1.0, 0.0])  # 1 m in front of eye 1, W
EYE1 = np.array([-0.075, 0.0, 0.0])
EYE2 = np.array([0.075, 0.0, 0.0])
CLICK = Click((320.0, 240.0), (320.3, 239.6), 0.5)
MATCH = Match(MatchStatus.OK, (300.0, 240.0), 0.97, 0.4, 0.01)


def _landing(camera: int, origin: np.ndarray, point: np.ndarray | None, body: str) -> Landing:
    """An eye's goal ray from ``origin`` through ``point`` (exact; None: it met nothing)."""
    aim = TARGET if point is None else point
    direction = (aim - origin) / np.linalg.norm(aim - origin)
    distance = math.inf if point is None else float(np.linalg.norm(point - origin))
    return Landing(camera, (320.0, 240.0), origin, direction, point, distance, body, body)


def _look(landing: Landing, seen_uv: tuple[float, float] = (320.0, 240.0)) -> Look:
    """A look at the fixation that saw the target at ``seen_uv``; truly at (320, 240)."""
    return Look(landing.camera, (0, 0, 0), landing, seen_uv, (320.0, 240.0))


def test_the_limit_is_one_percent_of_depth_but_at_least_5_mm() -> None:
    assert false_fixation_limit_m(0.3) == FALSE_FIXATION_MIN_M == 0.005
    assert false_fixation_limit_m(2.0) == pytest.approx(0.02)


@pytest.mark.parametrize(("off_m", "false"), [(0.004, False), (0.012, True), (0.05, True)])
def test_an_ok_fixation_landed_beyond_the_limit_is_false(off_m: float, false: bool) -> None:
    # Eye 1 landed ``off_m`` beside the target on a wall at 1 m (limit: 1 % of 1 m);
    # eye 2 looks exactly at eye 1's point: no vergence error, yet a false fixation.
    landed = TARGET + np.array([off_m, 0.0, 0.0])
    looks = {
        1: _look(_landing(1, EYE1, landed, "wall")),
        2: _look(_landing(2, EYE2, landed, "wall"), (323.0, 244.0)),
    }
    score = score_fixation(looks, TARGET, 1.0, True, CLICK, MATCH)
    assert score.false_fixation is false
    assert score.false_fixation_limit_m == pytest.approx(0.01)
    assert score.error_m[0] == pytest.approx(off_m, rel=1e-9)
    assert score.vergence_error_deg == pytest.approx(0.0, abs=1e-9)
    assert score.error_deg[0] > 0 and score.landed == ("wall", "wall")
    assert score.click_error_px == pytest.approx(0.5)
    assert (score.match_score, score.match_ambiguity, score.match_status) == (0.97, 0.4, "ok")
    # Eye 2's image put the target 3 px right and 4 px down of where it truly was.
    assert score.image_error_px == (0.0, pytest.approx(5.0))
    assert score.match_sigma_px == 0.01


def test_vergence_error_is_eye_2_off_eye_1s_point_and_a_failure_is_no_false_fixation() -> None:
    # Eye 2 aimed 0.5 degree off eye 1's point: that is the vergence error.
    one = _landing(1, EYE1, TARGET, "wall")
    to_point = TARGET - EYE2
    turn = math.radians(0.5)
    c, s = math.cos(turn), math.sin(turn)
    aimed = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ to_point
    two = _landing(2, EYE2, EYE2 + aimed, "wall")
    score = score_fixation({1: _look(one), 2: _look(two)}, TARGET, 1.0, True, CLICK, MATCH)
    assert score.vergence_error_deg == pytest.approx(0.5, rel=1e-9)
    assert not score.false_fixation  # eye 1 is on the target
    # An ok measurement whose eye 1 met nothing is false; a failed one is a failure.
    nothing = _landing(1, EYE1, None, "")
    assert score_fixation({1: _look(nothing)}, TARGET, 1.0, True, CLICK, None).false_fixation
    failed = score_fixation({1: _look(nothing)}, TARGET, 1.0, False, CLICK, None)
    assert not failed.false_fixation and math.isnan(failed.vergence_error_deg)
    assert failed.match_score is None and math.isnan(failed.error_m[1])
    assert math.isnan(failed.image_error_px[1])


def test_eye_2_on_the_wall_behind_is_a_false_fixation_though_eye_1_is_on_the_target() -> None:
    # A confident wrong correspondence: eye 1 on the target, eye 2's ray on a wall 0.8 m
    # beyond it.  An eye with no look at the fixation is unknown, not false.
    one = _landing(1, EYE1, TARGET, "box")
    wall = EYE2 + 1.8 * (TARGET + np.array([0.02, 0.0, 0.0]) - EYE2)
    two = _landing(2, EYE2, wall, "wall")
    score = score_fixation({1: _look(one), 2: _look(two)}, TARGET, 1.0, True, CLICK, MATCH)
    assert score.false_fixation and score.error_m[1] > 0.5
    assert score.landed == ("box", "wall") and score.vergence_error_deg > 0.5
    alone = score_fixation({1: _look(one)}, TARGET, 1.0, True, CLICK, MATCH)
    assert not alone.false_fixation


def test_a_confident_match_far_off_is_wrong_though_the_measurement_failed() -> None:
    # Camera 2's last confident look put the clicked point 20 px from where it truly was;
    # at 1 m the limit, 10 mm, is 8.4 px at 840 px focal length.  The measurement failed
    # after it: no false fixation, but a wrong match, counted.
    nothing = _landing(1, EYE1, None, "")
    far = Look(2, (0, 0, 0), _landing(2, EYE2, TARGET, "wall"), (340.0, 240.0), (320.0, 240.0))
    near = Look(2, (0, 0, 0), _landing(2, EYE2, TARGET, "wall"), (324.0, 240.0), (320.0, 240.0))
    wrong = score_fixation({1: _look(nothing)}, TARGET, 1.0, False, CLICK, MATCH, far, 840.0)
    assert wrong.wrong_match and not wrong.false_fixation
    assert wrong.match_error_px == pytest.approx(20.0)
    right = score_fixation({}, TARGET, 1.0, False, CLICK, MATCH, near, 840.0)
    assert not right.wrong_match and right.match_error_px == pytest.approx(4.0)
    unknown = score_fixation({}, TARGET, 1.0, False, CLICK, MATCH)
    assert not unknown.wrong_match and math.isnan(unknown.match_error_px)


def _doc(procedure: str, room: dict) -> dict:
    return {"description": "d", "experiment": {"procedure": procedure}, "scene": {"room": room}}


def test_surface_targets_need_no_markers_and_a_procedure_that_measures_them() -> None:
    scenario = scenario_from_document(_doc("model2", {"clutter": 0, "targets": 3}), "s")
    spec = scenario.scene.surface_targets
    assert spec is not None and spec.count == 3 and scenario.scene.targets == ()
    assert spec.depth_m == (0.3, 2.0) and spec.band_px == 10.0
    with pytest.raises(ScenarioError, match="no target to measure"):  # 0: none, no markers
        scenario_from_document(_doc("model2", {"clutter": 0, "targets": 0}), "s")
    with pytest.raises(ScenarioError, match=r"scene\.room\.targets") as caught:
        scenario_from_document(_doc("stereo", {"targets": 2}), "s")
    assert "model2 or model1 or fixation" in str(caught.value) and "\n" not in str(caught.value)


def test_natural_field_fast_measures_clicked_points_and_writes_where_the_eyes_landed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["run", "natural_field", "--fast", "--out", str(tmp_path), "--no-progress"])
    out = capsys.readouterr().out
    results = json.loads((tmp_path / "results.json").read_text())
    drawn = results["experiment"]["surface_targets"]
    measurements = results["measurements"]
    assert len(measurements) == drawn["asked"] >= 2
    ok = [m for m in measurements if m["status"] == "ok"]
    assert ok and code == (0 if len(ok) == len(measurements) else 1), out
    for m in ok:
        f = m["fixation"]
        values = [f["vergence_error_deg"], *f["error_deg"], *f["error_m"], f["click_error_px"]]
        assert all(math.isfinite(v) for v in values), f
        assert f["landed"][0] and f["landed"][1]  # both eyes' rays met an object of the room
        target = next(t for t in drawn["targets"] if t["name"] == m["name"])
        assert m["truth_world_m"] == pytest.approx(target["point_world_m"], abs=1e-9)
        # The estimate is of the clicked surface point: within a few % of its depth.
        assert m["error_pct_of_depth"] < 5.0
    assert drawn["false_fixations"] == sum(m["fixation"]["false_fixation"] for m in ok)
    assert "markerless fixations" in out and "false fixations" in out


def test_model1_lands_both_eyes_on_the_clicked_point_where_it_measures_it() -> None:
    # natural_field with the neck (Model 1), its fast calibration (the reference rows the
    # band needs): each eye's landing is taken on the row its own image showed the point
    # at the fixation's pose.
    with (SCENARIOS / "natural_field.toml").open("rb") as handle:
        doc = tomllib.load(handle)
    doc["experiment"]["procedure"] = "model1"
    doc["experiment"]["calibration"]["targets"] = 8
    doc["scene"]["room"]["targets"] = 4
    doc.pop("fast")
    result = run_scenario(scenario_from_document(doc, "natural_field_model1"))
    assert len(result.records) == 4
    ok = [r for r in result.records if r.measurement.ok]
    assert ok, result.failures
    for record in ok:
        f = record.fixation
        assert f is not None and all(f.landed)
        # Both eyes near one point: the goal row alone (their mean) put each 4-9 degrees off
        # on this head, whose reference rows lie 110 px apart.
        assert f.vergence_error_deg < 1.0, f
        assert max(f.error_deg) < 1.0, f
