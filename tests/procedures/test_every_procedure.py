"""Every registered procedure, the way dm_control's suite_test covers every task: its shipped
scenario's fast variant runs through the command line, its results block reads back as its
declared result type and is written again unchanged, every key of it has a meaning that type
declares, and every key of its own scenario tables is in the key reference."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from typing import Any

import pytest
from shipped_runs import ShippedRun

from headsim.codec import declaration, decode, encode
from headsim.files import to_jsonable
from headsim.procedures.contract import Procedure, get, names
from headsim.runs.results_reference import documented_paths, undocumented
from headsim.scenario.key_reference import descriptions
from headsim.scenario.loading import read_toml, scenario_files

PROCEDURES = names()


def shipped_scenario(procedure: str) -> str:
    """The shipped scenario named as the procedure, else the first one that runs it."""
    runs = sorted(
        path.stem
        for path in scenario_files()
        if read_toml(path).get("experiment", {}).get("procedure") == procedure
    )
    assert runs, f"no shipped scenario runs {procedure!r}"
    return procedure if procedure in runs else runs[0]


def read_back(procedure: Procedure, block: dict[str, Any]) -> object:
    """``block`` (without ``procedure``) read as the first of the procedure's result types
    that reads it (its fields not written, and without a default, given as None)."""
    kinds = procedure.result if isinstance(procedure.result, tuple) else (procedure.result,)
    errors = []
    for kind in kinds:
        unwritten = {
            f.name: None
            for f in dataclasses.fields(kind)
            if declaration(f).skip
            and f.default is dataclasses.MISSING
            and f.default_factory is dataclasses.MISSING
        }
        try:
            return decode(kind, block, **unwritten)
        except (KeyError, TypeError, ValueError) as error:
            errors.append(f"{kind.__name__}: {error}")
    raise AssertionError("; ".join(errors))


def test_the_procedures_are_listed_by_their_declared_rank() -> None:
    ranked = [get(name) for name in PROCEDURES]
    assert [(p.rank, p.name) for p in ranked] == sorted((p.rank, p.name) for p in ranked)
    assert {"model2", "model1", "calibration", "pursuit", "stereo"} <= set(PROCEDURES)


@pytest.mark.parametrize("procedure", PROCEDURES)
def test_its_shipped_scenario_runs_and_every_results_key_has_a_meaning(
    procedure: str, shipped_fast_run: Callable[[str], ShippedRun]
) -> None:
    run = shipped_fast_run(shipped_scenario(procedure))
    assert run.code in (0, 1), run.out  # 1: a measurement failed, by a counted cause
    results = json.loads((run.directory / "results.json").read_text())
    assert results["experiment"]["procedure"] == procedure
    block = {k: v for k, v in results["experiment"].items() if k != "procedure"}
    result = read_back(get(procedure), block)
    assert json.loads(json.dumps(to_jsonable(encode(result)))) == block
    assert [k for k in undocumented(results) if k.startswith("experiment")] == []
    declared = {f"experiment.{k}" for k in get(procedure).results}
    held = {p for p in documented_paths(results) if p.startswith("experiment.")}
    assert held - {"experiment.procedure"} <= declared


@pytest.mark.parametrize("procedure", PROCEDURES)
def test_its_scenario_tables_are_in_the_key_reference(procedure: str) -> None:
    meanings = descriptions()
    for section in get(procedure).keys:
        assert meanings[section.path] == section.meaning
        paths = {f"{section.key_path}.{d.name}": d.meaning for d in section.keys}
        assert {p: meanings.get(p) for p in paths} == paths
        assert all("\n" not in m and 0 < len(m) <= 200 for m in (section.meaning, *paths.values()))
        assert section.path.split(".")[0] in ("scene", "experiment")
