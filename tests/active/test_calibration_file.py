"""Calibrate once: ``headsim calibrate`` writes a head file that scenarios use, for that head only."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from headsim.active.calibration_file import (
    CalibrationFileError,
    head_fields,
    head_hash,
    read_calibration,
    write_calibration,
)
from headsim.active.calibration_report import CalibrationReport
from headsim.active.measurement import HeadKnowledge
from headsim.cli import main
from headsim.codec import decode
from headsim.runs.results_reference import CALIBRATION_FILE_FIELDS
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario
from headsim.scenario.tables import ScenarioError
from headsim.sim.settings import HeadBelief, HeadSettings, paper_head

SCENARIO = """description = "measure with a stored calibration"
[head]
preset = "realistic"
{extra}
[cam1]
noise_std = 1.0
[cam2]
noise_std = 1.0
[experiment]
procedure = "model2"
[experiment.calibration]
from = "{head}"
[[scene.targets]]
name = "near"
position_head_m = [0.04, 0.02, 0.5]
"""


def test_the_head_a_calibration_holds_for_leaves_out_seed_and_noise() -> None:
    head = paper_head()
    fields = head_fields(head)
    assert fields["cam1.kx"] == head.cameras[0].kx
    assert fields["baseline_m"] == head.baseline_m
    assert not any(name.endswith(("seed", "noise_std")) for name in fields)
    noisy = replace(head, seed=9, cameras=tuple(replace(c, noise_std=3.0) for c in head.cameras))
    assert head_hash(noisy) == head_hash(head)
    other = replace(head, cameras=(replace(head.cameras[0], kx=800.0), head.cameras[1]))
    assert head_hash(other) != head_hash(head)
    assert head_hash(HeadSettings()) != head_hash(head)


def test_calibrate_once_then_measure_with_it(tmp_path: Path, capsys) -> None:
    head_file = tmp_path / "head.json"
    assert main(["calibrate", "quickstart", "--fast", "--out", str(head_file)]) == 0
    assert "alpha_e1" in capsys.readouterr().out
    stored = json.loads(head_file.read_text())
    assert stored["format"] == "headsim-calibration/1"
    # Every key written is in the reference, and every key of the reference is written.
    written = [*stored, *(f"head.{key}" for key in stored["head"])]
    assert sorted(written) == sorted(CALIBRATION_FILE_FIELDS)
    assert stored["head"]["hash"] == head_hash(load_scenario("quickstart").settings)
    block = stored["calibration"]
    assert block["status"] == "ok" and block["render_counts"]["previews"] > 0
    assert len(block["alpha_e_std_rad"]) == 2 and block["vertical_reference"] is not None
    # Read back, the block is the report that was written, and writes the same bytes.
    again = write_calibration(
        tmp_path / "again.json",
        load_scenario("quickstart").settings,
        decode(CalibrationReport, block),
        stored["scenario"],
        stored["seed"],
    )
    assert again.read_bytes() == head_file.read_bytes()

    scenario_file = tmp_path / "measure.toml"
    scenario_file.write_text(SCENARIO.format(head=head_file, extra=""))
    scenario = load_scenario(scenario_file)
    # The reader read the file once; the run reads it no more, unless the head changed.
    other = replace(scenario.settings, baseline_m=0.16)
    with pytest.raises(CalibrationFileError, match=r"different head: baseline_m"):
        run_scenario(replace(scenario, settings=other))
    away = head_file.rename(tmp_path / "away.json")
    result = run_scenario(scenario)
    away.rename(head_file)
    assert result.ok
    assert result.renders.calibration.total == 0 and result.renders.overall.total > 0
    assert result.calibration is not None and result.calibration.source is not None
    assert result.calibration.source.render_counts is not None
    assert result.calibration.source.render_counts.total == block["render_counts"]["total"]
    assert result.calibration is not None
    assert result.calibration.source is not None
    assert result.calibration.source.path == str(head_file)
    assert result.calibration.alpha_e_rad == block["alpha_e_rad"]
    assert result.records[0].knowledge == "calibrated"
    # The measurement used the stored directions: a millimetre or two at 0.5 m (0.2 %
    # from an 8-ball calibration of this head; its initial directions alone, 0.058 and
    # -0.025 rad, unknown, would put the depth off by centimetres).
    assert result.records[0].measurement.error_pct_of_depth < 0.5

    # A relative path is relative to the scenario file, wherever the run starts.
    scenario_file.write_text(SCENARIO.format(head="head.json", extra=""))
    relative = load_scenario(scenario_file).experiment.calibration
    assert relative is not None and relative.source == str(head_file)

    # Another head refuses the file and says which setting differs (exit 2).
    other = tmp_path / "other.toml"
    other.write_text(SCENARIO.format(head=head_file, extra="baseline_m = 0.16"))
    with pytest.raises(ScenarioError, match=r"different head: baseline_m \(file 0.15"):
        load_scenario(other)
    assert main(["run", str(other), "--out", str(tmp_path / "out")]) == 2
    assert "baseline_m" in capsys.readouterr().err


def test_unusable_calibration_files_are_refused(tmp_path: Path) -> None:
    head = paper_head()
    missing = tmp_path / "missing.json"
    with pytest.raises(CalibrationFileError, match="cannot read"):
        read_calibration(missing, head)
    broken = tmp_path / "broken.json"
    broken.write_text("{")
    with pytest.raises(CalibrationFileError, match="not JSON"):
        read_calibration(broken, head)
    foreign = tmp_path / "foreign.json"
    foreign.write_text(json.dumps({"metrics": {}}))
    with pytest.raises(CalibrationFileError, match="not a calibration file"):
        read_calibration(foreign, head)
    partial = tmp_path / "partial.json"
    partial.write_text(json.dumps({"format": "headsim-calibration/1", "head": {}}))
    with pytest.raises(CalibrationFileError, match="malformed"):
        read_calibration(partial, head)


def test_calibrate_refuses_bad_input(tmp_path: Path, capsys) -> None:
    # A scenario without a calibration to run, and an output that is a directory.
    plain = tmp_path / "plain.toml"
    plain.write_text(
        SCENARIO.replace('[experiment.calibration]\nfrom = "{head}"\n', "").format(extra="")
    )
    assert main(["calibrate", str(plain), "--out", str(tmp_path / "h.json")]) == 2
    assert "experiment.calibration" in capsys.readouterr().err
    assert main(["calibrate", "quickstart", "--fast", "--out", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err


def test_a_told_knowledge_is_written_and_read_back_but_not_a_belief(tmp_path: Path) -> None:
    settings = load_scenario("quickstart").settings
    told = HeadKnowledge(alpha_e=(0.05, -0.02), v0=(240.5, None), los_offset_m=(0.001, 0.0))
    path = write_calibration(tmp_path / "told.json", settings, told, "told", 3)
    stored = read_calibration(path, settings)
    assert (stored.knowledge, stored.scenario, stored.seed) == (told, "told", 3)
    believing = HeadKnowledge(belief=HeadBelief(baseline_m=0.16))
    with pytest.raises(ValueError, match="holds no belief"):
        write_calibration(tmp_path / "no.json", settings, believing, "told", 3)
