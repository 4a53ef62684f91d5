"""The scenario-key reference: every key the loader accepts has a meaning, and each
meaning names a key; the type, range and default are the getters' own."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from headsim.scenario.key_reference import accepted_keys, collect_uses, descriptions
from headsim.scenario.loading import load_scenario
from headsim.scenario.tables import ScenarioError, collecting_keys, key_path

ROOT = Path(__file__).resolve().parents[2]
GETTERS = {"number", "integer", "boolean", "string", "choice", "numbers", "table", "tables", "has"}


@pytest.fixture(scope="module")
def uses() -> dict:
    return collect_uses()


def test_every_accepted_key_has_a_meaning_and_every_meaning_a_key(uses: dict) -> None:
    meanings = descriptions()
    assert [k for k in uses if not meanings.get(k)] == []
    assert [k for k in meanings if k not in uses] == []
    assert all("\n" not in d and len(d) <= 200 for d in meanings.values())


def test_every_key_a_reader_names_is_reached_by_the_reference_documents(uses: dict) -> None:
    # A key read in a branch that no shipped scenario and no variant takes would be
    # missing from the reference: every string key passed to a getter must be a leaf.
    leaves = {path.rsplit(".", 1)[-1].removesuffix("[]") for path in uses}
    named = set()
    for folder in ("headsim/scenario", "headsim/procedures"):
        for source in sorted((ROOT / folder).glob("*.py")):
            for node in ast.walk(ast.parse(source.read_text())):
                if (
                    isinstance(node, ast.Call)
                    and isinstance(node.func, ast.Attribute)
                    and node.func.attr in GETTERS
                    and node.args
                    and isinstance(node.args[0], ast.Constant)
                    and isinstance(node.args[0].value, str)
                ):
                    named.add(node.args[0].value)
    assert sorted(named - leaves) == []


def test_the_getters_own_limits_and_defaults_reach_the_reference(uses: dict) -> None:
    baseline = uses["head.baseline_m"]
    assert baseline.kind == "number" and baseline.allowed.startswith("a number >= 0.01 and <= 1 m")
    assert uses["seed"].default == "0" and uses["description"].default == ""  # required
    assert uses["scene.targets[].body"].allowed.startswith("marker_red, ")
    assert uses["head.neck_d1_m"].default == "depends on other keys"  # the preset's
    keys = {k.path: k for k in accepted_keys()}
    assert keys["experiment.servo.tolerance_px"].description.endswith("px.")


def test_a_key_the_reference_does_not_know_is_refused_by_the_loader(tmp_path: Path) -> None:
    # The reference lists what the loader accepts: a key outside it is an error there.
    path = tmp_path / "mine.toml"
    path.write_text('description = "x"\n[head]\nbaseline_mm = 150\n')
    with pytest.raises(ScenarioError, match=r"head\.baseline_mm: unknown key"):
        load_scenario(path)


def test_collecting_notes_nothing_outside_and_indices_as_brackets() -> None:
    assert key_path("scene.targets[12].position_head_m[0]") == "scene.targets[].position_head_m[]"
    load_scenario("quickstart")  # outside collecting_keys: no state kept anywhere
    with collecting_keys() as seen:
        load_scenario("quickstart")
    assert "experiment.calibration.targets" in seen and "scene" in seen
