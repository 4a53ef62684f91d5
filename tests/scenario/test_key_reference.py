"""The scenario-key reference, made from the declarations alone: every key has a meaning;
every key a reader names is declared; and every declared key is read through its
declaration, so a value outside it is refused naming the key and what the reference says
is allowed."""

from __future__ import annotations

import ast
import re
from pathlib import Path
from typing import Any

import pytest

from headsim.scenario.key_reference import Key, accepted_keys, descriptions, sections
from headsim.scenario.loading import (
    load_scenario,
    read_toml,
    resolve_path,
    scenario_files,
    scenario_from_document,
)
from headsim.scenario.schema import declared_keys
from headsim.scenario.tables import ScenarioError, declared_use
from headsim.sim import heads
from headsim.sim.declared import Array, Choice, Declared, Flag, Section, Setting, Text

ROOT = Path(__file__).resolve().parents[2]
GETTERS = {"number", "integer", "boolean", "string", "choice", "numbers", "table", "tables", "has"}


def key_path(field_path: str) -> str:
    """``field_path`` with list indices as ``[]``: ``scene.targets[3].name`` -> ``scene.targets[].name``."""
    return re.sub(r"\[\d+\]", "[]", field_path)


@pytest.fixture(scope="module")
def keys() -> dict[str, Key]:
    return {k.path: k for k in accepted_keys()}


def test_every_accepted_key_has_a_meaning(keys: dict[str, Key]) -> None:
    assert [p for p, k in keys.items() if not k.description] == []
    assert [p for p, k in keys.items() if not k.kind] == []
    assert all("\n" not in k.description and len(k.description) <= 200 for k in keys.values())
    assert descriptions() == {p: k.description for p, k in keys.items()}


def test_every_key_a_reader_names_is_declared(keys: dict[str, Key]) -> None:
    # A key read by name, not through its declaration, must still be a declared one.
    leaves = {path.rsplit(".", 1)[-1].removesuffix("[]") for path in keys}
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


def test_the_declared_limits_and_defaults_reach_the_reference(keys: dict[str, Key]) -> None:
    baseline = keys["head.baseline_m"]
    assert baseline.kind == "number" and baseline.allowed.startswith("a number >= 0.01 and <= 1 m")
    assert keys["seed"].default == "0" and keys["description"].default == ""  # required
    assert keys["scene.targets[].body"].allowed.startswith("marker_red, ")
    assert keys["scene.targets[].name"].default == "depends on other keys"  # target_N
    assert keys["head.neck_d1_m"].default == "depends on other keys"  # the preset's
    assert keys["scene.room.targets"].kind == "integer or tables"
    assert keys["experiment.servo.tolerance_px"].description.endswith("px.")


def test_a_key_the_reference_does_not_know_is_refused_by_the_loader(tmp_path: Path) -> None:
    # The reference lists what the loader accepts: a key outside it is an error there.
    path = tmp_path / "mine.toml"
    path.write_text('description = "x"\n[head]\nbaseline_mm = 150\n')
    with pytest.raises(ScenarioError, match=r"head\.baseline_mm: unknown key"):
        load_scenario(path)


def _outside(decl: Declared) -> object:
    """A value the declaration refuses: the wrong type, or below its range."""
    if isinstance(decl, (Flag, Text, Array)):
        return 5
    if isinstance(decl, Choice):
        return "no_such_choice"
    below = int(decl.lo) - 1 if decl.integer else decl.lo - 1.0
    return [below] * decl.count if decl.count > 1 else below


def _declared_paths() -> list[object]:
    paths = ((f"{table}.{d.name}" if table else d.name, d) for table, d in declared_keys())
    return [pytest.param(path, decl, id=path) for path, decl in paths]


@pytest.mark.parametrize(("path", "decl"), _declared_paths())
def test_a_declared_keys_error_says_what_its_reference_entry_allows(
    path: str, decl: Declared, keys: dict[str, Key]
) -> None:
    """The loader's one-line error for a declared key and the reference's entry come from the
    one declaration: a value outside it is refused naming the key and what the reference
    says is allowed (the principal point's upper end is the image's, tighter than any
    image's)."""
    entry = keys[path]
    assert entry.description == decl.meaning and decl.meaning
    with pytest.raises(ScenarioError) as refused:
        load_scenario("quickstart", overrides={path: _outside(decl)})
    message = str(refused.value)
    assert f": {refused.value.field}: " in message
    assert key_path(refused.value.field).removesuffix("[]") == path
    if isinstance(decl, Setting) and decl.name in ("cx", "cy"):
        assert refused.value.allowed == entry.allowed.replace(
            "4095", "639" if decl.name == "cx" else "479"
        )
    elif isinstance(decl, Array):
        assert refused.value.allowed == entry.allowed
        assert refused.value.problem.startswith("must be an array")
    else:
        assert refused.value.allowed == entry.allowed
    assert "\n" not in message


def _mapping() -> dict[str, Any]:
    """The independent-eyes head's mapping as a user's ``[head.mapping]`` would give it."""
    mapping = heads.shipped("independent_eyes").mapping
    given = {d.name: getattr(mapping, d.name) for d in heads.MAPPING.keys}
    return {k: list(v) if isinstance(v, tuple) else v for k, v in given.items() if v is not None}


_PATH = "scene.pursuit.path"
_START = [0.0, 1.0, 0.21]
#: Each kind of pursuit path the shipped scenario does not take, and its optional keys.
_KINDS: tuple[tuple[dict[str, Any], tuple[str, ...]], ...] = (
    ({"kind": "sinusoid", "centre_world_m": _START, "amplitude_m": [0.1, 0, 0.05],
      "frequency_hz": 0.5}, ("phase_rad",)),
    ({"kind": "random_walk", "start_world_m": _START, "max_speed_m_s": 0.3},
     ("seed", "box_half_m")),
    ({"kind": "throw", "start_world_m": _START, "velocity_m_s": [0, 0, 1.5]}, ()),
    ({"kind": "jump", "start_world_m": _START, "end_world_m": [0.1, 1.0, 0.25], "time_s": 0.1},
     ()),
    ({"kind": "static", "point_world_m": _START}, ()),
)  # fmt: skip
_TETRAHEDRON = {
    "name": "tetra",
    "shape": "mesh",
    "pos_world_m": [0.0, 1.0, 0.0],
    "vertices_m": [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
    "faces": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
}
_RANDOM_WAYPOINTS = {
    "scene.moving_target.waypoints_world_m": None,
    "scene.moving_target.waypoints_head_m": None,
    "scene.moving_target.random": {"waypoints": 3},
}
#: Where no shipped scenario takes a table or a branch: the scenario and the fields to set
#: first (None: removed), by section path or key path.
BRANCHES: dict[str, tuple[str, dict[str, Any]]] = {
    "head.mapping": (
        "quickstart",
        {"head.model": str(ROOT / "models" / "independent_eyes.xml"), "head.mapping": _mapping()},
    ),
    "scene.moving_target.random": ("tracking", _RANDOM_WAYPOINTS),
    "scene.random_objects": (
        "relative_positioning",
        {"scene.objects": None, "scene.random_objects": {"count": 3}},
    ),
    "scene.room.targets": (
        "natural_field",
        {"scene.room.targets": [{"name": "on_wall", "point_world_m": [0.0, 3.0, 0.5]}]},
    ),
    "scene.room.targets[].point_object_m": (
        "natural_field",
        {"scene.room.targets": [{"name": "on", "object": "poster", "point_object_m": [0, 0, 0]}]},
    ),
    "scene.room.objects[].vertices_m": ("natural_field", {"scene.room.objects": [_TETRAHEDRON]}),
    "scene.room.objects[].faces": ("natural_field", {"scene.room.objects": [_TETRAHEDRON]}),
    **{
        f"{_PATH}.{key}": ("pursuit", {_PATH: path, "scene.pursuit.duration_s": 0.4})
        for path, optional in _KINDS
        for key in (*path, *optional)
        if key != "kind"
    },
}


#: Keys whose upper end the reader tightens from another key (the meaning says which).
TIGHTENED = {"scene.pursuit.live.exposure_s"}


def _edited(doc: dict[str, Any], dotted: str, value: Any) -> dict[str, Any]:
    """A copy of ``doc`` with the field at ``dotted`` set (None: removed); ``[0]`` steps
    into an array's first entry."""
    name, _, rest = dotted.partition(".")
    index = None
    if name.endswith("[0]"):
        name, index = name[:-3], 0
    out = dict(doc)
    if not rest:
        if value is None:
            out.pop(name, None)
        else:
            out[name] = value
        return out
    child = out.get(name, {})
    if index is not None:
        child = list(child)
        child[index] = _edited(child[index], rest, value)
        out[name] = child
    else:
        out[name] = _edited(child, rest, value)
    return out


def _holds(doc: dict[str, Any], dotted: str) -> bool:
    """Whether ``doc`` has the table at ``dotted`` (an array of tables: a non-empty one)."""
    node: Any = doc
    for part in dotted.split("."):
        if isinstance(node, list):
            node = node[0]
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
    return isinstance(node, dict) or (isinstance(node, list) and bool(node))


def _section_keys() -> list[object]:
    return [
        pytest.param(section, decl, id=f"{section.key_path}.{decl.name}")
        for section in sections()
        for decl in section.keys
    ]


def _document(section: Section, decl: Declared) -> tuple[str, dict[str, Any]]:
    """A shipped scenario that reaches ``decl``'s key, with the fields that take its branch."""
    key = f"{section.key_path}.{decl.name}"
    name, fields = BRANCHES.get(key) or BRANCHES.get(section.path) or ("", {})
    if not name:
        holding = [p.stem for p in scenario_files() if _holds(read_toml(p), section.path)]
        assert holding, f"no shipped scenario has [{section.path}], and no branch given"
        name = holding[0]
    doc = read_toml(resolve_path(name))
    for dotted, value in fields.items():
        doc = _edited(doc, dotted, value)
    return name, doc


@pytest.mark.parametrize(("section", "decl"), _section_keys())
def test_every_key_of_a_table_is_read_through_its_declaration(
    section: Section, decl: Declared
) -> None:
    """Each declared key is read where its table is: the scenario as it is loads, and a
    value outside the declaration is refused naming the key (not as unknown), with what
    the reference allows where the declaration alone bounds it."""
    path = f"{section.key_path}.{decl.name}"
    name, doc = _document(section, decl)
    directory = resolve_path(name).parent
    scenario_from_document(doc, name, directory=directory)  # the branch itself is valid
    dotted = path.replace("[]", "[0]")
    with pytest.raises(ScenarioError) as refused:
        scenario_from_document(_edited(doc, dotted, _outside(decl)), name, directory=directory)
    error = refused.value
    assert key_path(re.sub(r"\[\d+\]$", "", error.field.removeprefix("fast."))) == path
    assert error.problem != "unknown key"
    assert "\n" not in str(error)
    if isinstance(decl, (Setting, Flag)) and path not in TIGHTENED:
        assert error.allowed == declared_use(decl)[1]
