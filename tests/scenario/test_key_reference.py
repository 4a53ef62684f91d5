"""The scenario-key reference: every key the loader accepts has a meaning, and each
meaning names a key; the type, range and default are the declarations' (or, for the
hand-written getters, the getters' own), and the loader's errors say the same."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from headsim.scenario.key_reference import accepted_keys, collect_uses, descriptions
from headsim.scenario.loading import load_scenario
from headsim.scenario.schema import declared_keys
from headsim.scenario.tables import ScenarioError, collecting_keys, key_path
from headsim.sim.declared import Choice, Declared, Flag, Setting, Text

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


def _declared_paths() -> list[object]:
    paths = ((f"{table}.{d.name}" if table else d.name, d) for table, d in declared_keys())
    return [pytest.param(path, decl, id=path) for path, decl in paths]


def _outside(decl: Declared) -> object:
    """A value the declaration refuses: the wrong type, or below its range."""
    if isinstance(decl, (Flag, Text)):
        return 5
    if isinstance(decl, Choice):
        return "no_such_choice"
    below = int(decl.lo) - 1 if decl.integer else decl.lo - 1.0
    return [below] * decl.count if decl.count > 1 else below


@pytest.mark.parametrize(("path", "decl"), _declared_paths())
def test_a_declared_keys_error_says_what_its_reference_entry_allows(
    path: str, decl: Declared, uses: dict
) -> None:
    """The loader's one-line error for a declared key and the reference's entry come from the
    one declaration: a value outside it is refused naming the key and what the reference
    says is allowed (the principal point's upper end is the image's, tighter than any
    image's)."""
    entry = uses[path]
    assert descriptions()[path] == decl.meaning and decl.meaning
    with pytest.raises(ScenarioError) as refused:
        load_scenario("quickstart", overrides={path: _outside(decl)})
    message = str(refused.value)
    assert f": {refused.value.field}: " in message
    assert key_path(refused.value.field).removesuffix("[]") == path
    if isinstance(decl, Setting) and decl.name in ("cx", "cy"):
        assert refused.value.allowed == entry.allowed.replace(
            "4095", "639" if decl.name == "cx" else "479"
        )
    else:
        assert refused.value.allowed == entry.allowed
    assert "\n" not in message
