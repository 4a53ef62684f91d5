"""The results.json reference: every key a real run writes has a meaning, every meaning a key."""

from __future__ import annotations

import json
import sys
from dataclasses import fields
from pathlib import Path

import pytest

from headsim.cli import main
from headsim.runs.results_reference import (
    MARKERLESS_ONLY,
    RESULTS_FIELDS,
    documented_paths,
    experiment_fields,
    undocumented,
)
from headsim.sim import imperfections, settings

TOOLS = Path(__file__).resolve().parents[2] / "tools"


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict]:
    """results.json of quickstart, tracking, independent_eyes and natural_field, fast:
    between them every key outside ``experiment`` (a calibration, random targets, Model 1,
    Model 2, fixation, a head other than the paper's, markerless targets; these may fail
    by a counted cause: exit 1)."""
    out = {}
    for name in ("quickstart", "tracking", "independent_eyes", "natural_field"):
        folder = tmp_path_factory.mktemp(name)
        code = main(["--quiet", "run", name, "--fast", "--out", str(folder), "--no-progress"])
        assert code in ((0, 1) if name == "natural_field" else (0,))
        out[name] = json.loads((folder / "results.json").read_text())
    return out


def test_every_meaning_names_a_key_that_a_real_run_writes(runs: dict[str, dict]) -> None:
    held = set().union(*(documented_paths(r) for r in runs.values()))
    # Written only by `headsim calibrate` and for a stored calibration (tests/run/test_serialise.py),
    # and only with an imperfection registered beyond the camera's fields (none is shipped).
    elsewhere = {"calibration.rendered_frames", "calibration.from", "settings.cameras[].extra"}
    assert [p for p in RESULTS_FIELDS if p not in held | elsewhere] == []
    assert all(undocumented(r) == [] for r in runs.values())
    assert {p for p in held if p.startswith("experiment.")} == {
        "experiment.procedure",
        *(f"experiment.{k}" for k in experiment_fields()["tracking"]),
        *(f"experiment.{k}" for k in MARKERLESS_ONLY),
    }


def test_a_key_without_a_meaning_is_named_by_its_path(runs: dict[str, dict]) -> None:
    results = json.loads(json.dumps(runs["quickstart"]))
    results["summary"]["calibrated"]["by_depth"][0]["median"] = 1.0
    results["scenario"]["scene"]["acceptance"]["kept"] = 3
    results["measurements"][0]["speed"] = 2.0
    results["experiment"]["times_s"] = []  # a tracking key in a model2 run
    assert undocumented(results) == [
        "experiment.times_s",
        "measurements[].speed",
        "scenario.scene.acceptance.kept",
        "summary.*.by_depth[].median",
    ]


def test_the_generated_page_lists_every_key_under_its_table() -> None:
    sys.path.insert(0, str(TOOLS))
    try:
        import docs_pages
    finally:
        sys.path.remove(str(TOOLS))
    page = docs_pages.results_json_page()
    assert "## `summary.*.by_depth[]`\n" in page and "| `band` | the band |" in page
    assert "### `relative_positioning`\n" in page and "| `objects[].margin_px` |" in page
    for path in RESULTS_FIELDS:
        assert f"| `{path.rpartition('.')[2]}` |" in page, path


def test_the_settings_rows_are_the_settings_declarations() -> None:
    """The ``settings`` block's meanings are the declared settings' own (sim/settings.py and
    each imperfection's module), one row per field of the records, in the order written."""
    declared = {s.name: s for s in (*settings.CAMERA_SETTINGS, *imperfections.all_settings())}
    for f in fields(settings.CameraSettings):
        if f.name != "extra":
            row = RESULTS_FIELDS[f"settings.cameras[].{f.name}"]
            assert row == declared[f.name].meaning.removesuffix(".")
    for setting in settings.HEAD_SETTINGS:
        assert RESULTS_FIELDS[f"settings.{setting.name}"] == setting.meaning.removesuffix(".")
    for setting in settings.BELIEF_SETTINGS:
        meaning = setting.meaning.removesuffix(".")
        assert RESULTS_FIELDS[f"belief.{setting.name}"] == meaning
        assert RESULTS_FIELDS[f"settings.belief.{setting.name}"] == meaning
    top = [p.removeprefix("settings.") for p in RESULTS_FIELDS if p.count(".") == 1]
    top = [p for p in top if p in {f.name for f in fields(settings.HeadSettings)}]
    assert top == [f.name for f in fields(settings.HeadSettings)]
