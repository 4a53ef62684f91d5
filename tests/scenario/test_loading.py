"""Loading scenario files: every shipped file validates in both variants; the fast table and missing or broken files say what is wrong."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from headsim.scenario.loading import load_scenario, scenario_files
from headsim.scenario.tables import ScenarioError

from .helpers import MINIMAL, write_scenario

FILES = scenario_files()


PAPER_SCENARIOS = ("calibration", "chessboard", "relative_positioning", "tracking")


def test_there_is_a_scenario_for_each_experiment_and_a_quick_start() -> None:
    assert {"quickstart", *PAPER_SCENARIOS} <= {p.stem for p in FILES}


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_every_scenario_file_validates_in_both_variants(path: Path) -> None:
    full, fast = load_scenario(path), load_scenario(path, fast=True)
    assert full.description == fast.description and "\n" not in full.description
    assert not full.fast and fast.fast
    if full.fixations:
        assert fast.fixations < full.fixations
    else:  # a procedure without fixations (zoom_fixed_points): fewer board poses
        assert fast.fixations == 0 and fast.experiment.block.poses < full.experiment.block.poses
    if path.stem in (*PAPER_SCENARIOS, "quickstart"):
        # The paper's cameras, and the initial directions calibrated before measuring.
        assert full.preset == fast.preset == ("realistic" if path.stem == "quickstart" else "paper")
        assert full.experiment.calibration is not None and fast.experiment.calibration is not None


def test_a_scenario_is_found_by_name_and_the_seed_draws_only_the_random_parts() -> None:
    one, other = load_scenario("quickstart"), load_scenario("quickstart", seed=7)
    assert one.seed == 0 and other.seed == other.settings.seed == 7
    explicit = [t for t in one.scene.targets if not t.name.startswith("random")]
    assert explicit == [t for t in other.scene.targets if not t.name.startswith("random")]
    randoms = [t.position_world_m for t in one.scene.targets if t.name.startswith("random")]
    assert randoms and randoms != [
        t.position_world_m for t in other.scene.targets if t.name.startswith("random")
    ]
    assert load_scenario("quickstart", seed=0) == one  # drawn again, the same


def test_the_fast_table_is_checked_and_named(tmp_path: Path) -> None:
    path = write_scenario(tmp_path, MINIMAL + "[fast]\nexperiment.calibration.targets = 1\n")
    with pytest.raises(
        ScenarioError,
        match=re.escape(f"{path}: fast.experiment.calibration.targets: 1 is out of range"),
    ):
        load_scenario(path)  # the full variant is fine, but both are checked
    path = write_scenario(tmp_path, MINIMAL + "[fast]\ndescription = 'short'\n")
    with pytest.raises(ScenarioError, match=r"fast.description: unknown key"):
        load_scenario(path)


def test_a_file_that_is_not_toml_or_not_there_says_so(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match=re.escape(f"{tmp_path / 'bad.toml'}: not valid TOML")):
        load_scenario(write_scenario(tmp_path, "description = \n"))
    with pytest.raises(
        ScenarioError, match=r"no such scenario file .allowed: a .toml path or one of: .*quickstart"
    ):
        load_scenario("kitchen")


def test_a_document_is_the_scenario_its_file_would_be(tmp_path: Path) -> None:
    import tomllib

    from headsim.scenario.loading import scenario_from_document

    path = write_scenario(tmp_path, MINIMAL, "minimal.toml")
    doc = tomllib.loads(path.read_text())
    from_file = load_scenario(path)
    from_doc = scenario_from_document(doc, "minimal", directory=tmp_path)
    assert from_doc == from_file and from_doc.path == path
    # Checked like a file: a target behind the head is refused, the document named.
    behind = {**doc, "scene": {"targets": [{"position_head_m": [0.0, 0.0, -0.5]}]}}
    with pytest.raises(ScenarioError, match=r"behind\.toml: scene\.targets\[0\]"):
        scenario_from_document(behind, "behind", directory=tmp_path)
