"""The summary a run prints, through the real CLI: each line says what it counts, and
where each believed quantity came from (results.json's ``belief.sources`` too)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from scenario.helpers import write_scenario

from headsim.cli import main
from headsim.sim.heads import SHIPPED

#: Two hand-placed markers on the ideal head, its true baseline changed in [head].
HAND_PLACED = """
description = "two markers placed by hand"

[head]
baseline_m = 0.1512

[experiment]
procedure = "model2"

[[scene.targets]]
name = "a"
position_head_m = [0.02, 0.01, 0.5]

[[scene.targets]]
name = "b"
position_head_m = [-0.03, 0.0, 1.1]
"""


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["run", *args, "--no-progress"])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def quickstart(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, dict]:
    out = tmp_path_factory.mktemp("quickstart")
    assert main(["--quiet", "run", "quickstart", "--fast", "--out", str(out)]) == 0
    return (out / "summary.txt").read_text(), json.loads((out / "results.json").read_text())


def test_quickstart_summary_names_each_line_once_and_labels_its_columns(
    quickstart: tuple[str, dict],
) -> None:
    text, results = quickstart
    assert text.count("head knew calibrated:") == 1
    assert "residual px (Ca1 Ca2)" in text
    assert "whole field" not in text  # two markers placed, one drawn
    assert "all 3 targets measured (2 placed by hand, 1 drawn over the field)" in text
    bands = {b["band"]: b["count"] for b in results["summary"]["calibrated"]["by_depth"]}
    empty = [band for band, count in bands.items() if count == 0]
    assert empty, bands  # the fast quick start leaves a band empty: it must say so
    for band in empty:
        assert f"{band}: no targets" in text
    assert "- % (0)" not in text


def test_quickstart_states_where_its_belief_came_from(quickstart: tuple[str, dict]) -> None:
    text, results = quickstart
    sources = results["belief"]["sources"]
    assert sources == dict.fromkeys(
        ("baseline_m", "neck_d1_m", "neck_a2_m", "nodal_offset_m", "side_offset_m"), "preset"
    )
    assert (
        "belief: baseline 150 mm, neck d1 120 mm, neck a2 90 mm, side offsets 0/0 mm: "
        "the preset's belief"
    ) in text.splitlines()


def test_a_belief_that_follows_the_truth_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_scenario(tmp_path, HAND_PLACED, "hand.toml")
    code, out, err = _run(capsys, str(path), "--out", str(tmp_path / "out"))
    assert code == 0, err
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["belief"]["baseline_m"] == results["settings"]["baseline_m"] == 0.1512
    assert results["belief"]["sources"]["baseline_m"] == "truth"
    assert results["belief"]["sources"]["neck_d1_m"] == "design"
    assert "belief: baseline 151.2 mm: equal to the truth (set in [head], no [belief])" in out
    assert "all 2 targets measured (placed by hand)" in out and "whole field" not in out

    told = HAND_PLACED.replace("[experiment]", "[belief]\nbaseline_m = 0.15\n\n[experiment]")
    path = write_scenario(tmp_path, told, "told.toml")
    code, out, err = _run(capsys, str(path), "--out", str(tmp_path / "told"))
    assert code == 0, err
    results = json.loads((tmp_path / "told" / "results.json").read_text())
    assert (results["belief"]["baseline_m"], results["belief"]["sources"]["baseline_m"]) == (
        0.15,
        "file",
    )
    assert "baseline 150 mm: from [belief]" in out


def test_a_believed_nodal_offset_is_refused_naming_the_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    told = HAND_PLACED.replace(
        "[experiment]", "[belief]\nnodal_offset_m = [0.05, 0.05]\n\n[experiment]"
    )
    path = write_scenario(tmp_path, told, "nodal.toml")
    code, _, err = _run(capsys, str(path), "--out", str(tmp_path / "out"))
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"headsim: error: {path}: belief.nodal_offset_m: no estimate")
    assert "allowed: leave it out" in lines[0]
    assert not (tmp_path / "out").exists()


def test_another_head_shows_no_paper_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = _run(capsys, "quickstart", "--fast", "--head", "icub", "--out", str(tmp_path))
    assert code == 0, err
    assert "the paper's" not in out
    calibration = out.split("Calibration of the initial directions")[1].splitlines()[1]
    assert calibration.split() == ["ours", "+-", "truth", "error"]
    assert out.startswith("quickstart (fast variant) with --head icub")
    assert "head: icub (version_vergence eyes), realistic preset" in out


def test_a_bad_head_flag_blames_the_flag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = _run(capsys, "quickstart", "--head", "bogus", "--out", str(tmp_path / "out"))
    assert code == 2
    assert err.strip() == (
        "headsim: error: --head: no shipped head or MJCF file 'bogus' (allowed: "
        f"{', '.join(SHIPPED)}, or a path to a head's MJCF .xml file)"
    )
    assert not (tmp_path / "out").exists()
