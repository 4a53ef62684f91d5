"""A procedure defined here, registered through the public registry and run by ``headsim run``:
its own ``[experiment.marker_height]`` key, its scene table, its results.json block, its
summary lines and its recording rows, and both generated reference pages, with no other
module edited."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import rerun as rr
from rerun.chunk import RrdReader

from headsim import procedures
from headsim.active.measurement import HeadKnowledge
from headsim.cli import main
from headsim.codec import declared, doc
from headsim.runs.context import simulator
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.recording import Recorder
from headsim.scenario.loading import load_scenario
from headsim.scenario.scene import targets_reader
from headsim.scenario.spec import CalibrationSpec, Scenario
from headsim.scenario.tables import Table
from headsim.sim import names
from headsim.sim.declared import Section, Setting

BODY = sorted(names.MARKER_COLOURS)[0]
TOOLS = Path(__file__).resolve().parents[2] / "tools"


@dataclass(frozen=True)
class HeightSpec:
    """``[experiment.marker_height]``: what is added to the height, m."""

    offset_m: float = 0.0


OFFSET = Setting("offset_m", 0.0, -1.0, 1.0, "m", "Added to the marker's height, m.")
BLOCK = Section("experiment.marker_height", "What the height procedure adds.", (OFFSET,))


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    block = table.section(BLOCK) or Table({}, BLOCK.path, table.ctx)
    offset_m = block.setting(OFFSET)
    block.done()
    return {"block": HeightSpec(offset_m)}


@declared
class HeightResult:
    """How high the scene's first target stands in W, m (the truth: this procedure only
    reads the scene)."""

    body: str = doc("the marker measured")
    height_m: float = doc("its height in W plus the offset, m")


def run_height(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], HeightResult]:
    placement = scenario.scene.targets[0]
    with simulator(hub, "default", scenario) as sim:
        sim.set_body_pose(placement.body, np.array(placement.position_world_m))
        offset_m = scenario.experiment.block.offset_m
        height_m = float(sim.position(placement.body)[2]) + offset_m
        return [], HeightResult(placement.body, height_m)


def rows(result: HeightResult, log: Recorder) -> None:
    log.rec.log("/results/height", rr.Scalars(result.height_m))


HEIGHT = procedures.Procedure(
    "marker_height",
    "default",
    run_height,
    HeightResult,
    summary=lambda r, paper: [f"Marker height: {r.body} at {r.height_m * 1000:.1f} mm"],
    rows=rows,
    options=read_options,
    read_scene=targets_reader("marker_height", required=True),
    fixations=lambda scenario: 0,  # it fixates nothing
    keys=(BLOCK,),
)


@pytest.fixture
def registered() -> Iterator[procedures.Procedure]:
    procedures.register(HEIGHT)
    yield HEIGHT
    del procedures.REGISTRY[HEIGHT.name]


def test_a_new_procedure_runs_through_headsim_run(
    registered: procedures.Procedure, tmp_path: Path
) -> None:
    scenario = tmp_path / "height.toml"
    scenario.write_text(
        'description = "How high a marker stands"\nseed = 0\n\n'
        '[experiment]\nprocedure = "marker_height"\n\n'
        "[experiment.marker_height]\noffset_m = 0.25\n\n"
        f'[[scene.targets]]\nbody = "{BODY}"\nposition_head_m = [0.02, 0.01, 0.6]\n'
    )
    loaded = load_scenario(scenario)
    assert [t.body for t in loaded.scene.targets] == [BODY] and loaded.fixations == 0
    out, rrd = tmp_path / "out", tmp_path / "height.rrd"
    argv = ["run", str(scenario), "--out", str(out), "--rrd", str(rrd), "--no-progress"]
    assert main(argv) == 0
    block: dict[str, Any] = json.loads((out / "results.json").read_text())["experiment"]
    assert block["procedure"] == "marker_height" and block["body"] == BODY
    assert block["height_m"] == pytest.approx(loaded.scene.targets[0].position_world_m[2] + 0.25)
    summary = (out / "summary.txt").read_text()
    assert f"Marker height: {BODY} at {block['height_m'] * 1000:.1f} mm" in summary
    assert "OK: 0 measurements, none failed" in summary
    values = [
        value
        for chunk in RrdReader(rrd).stream().filter(content="/results/height")
        for value in chunk.to_record_batch().column("Scalars:scalars").to_pylist()
    ]
    assert len(values) == 1 and np.allclose(np.ravel(values), block["height_m"])


def test_a_name_taken_twice_is_refused(registered: procedures.Procedure) -> None:
    with pytest.raises(ValueError, match="already registered"):
        procedures.register(
            procedures.Procedure("marker_height", "default", run_height, HeightResult)
        )
    assert procedures.get("marker_height") is HEIGHT
    assert {"model2", "pursuit", "marker_height"} <= set(procedures.names())


def test_a_new_procedure_appears_in_both_generated_references(
    registered: procedures.Procedure,
) -> None:
    sys.path.insert(0, str(TOOLS))
    try:
        import docs_pages
    finally:
        sys.path.remove(str(TOOLS))
    results = docs_pages.results_json_page()
    section = results[results.index("### `marker_height`") :]
    assert "| `body` | the marker measured |" in section
    assert "| `height_m` | its height in W plus the offset, m |" in section
    keys = docs_pages.scenario_keys_page()
    assert "| `experiment.marker_height.offset_m` | number | a number >= -1 and <= 1 m |" in keys
    assert "Added to the marker's height, m. |" in keys


def test_the_first_lookups_from_many_threads_all_see_every_procedure() -> None:
    # A batch of heads or a sweep's workers look procedures up at once in a fresh
    # process: none may see the registry half filled ("unknown value 'model2'").
    script = (
        "import threading, headsim\n"
        "from headsim.procedures import contract\n"
        "seen = []\n"
        "def look():\n"
        "    seen.append(set(contract.names()))\n"
        "threads = [threading.Thread(target=look) for _ in range(16)]\n"
        "[t.start() for t in threads]\n"
        "[t.join() for t in threads]\n"
        "print(sum('model2' in s and len(s) >= 10 for s in seen))\n"
    )
    for _ in range(3):
        out = subprocess.run(
            [sys.executable, "-c", script], capture_output=True, text=True, check=True
        ).stdout
        assert out.strip() == "16"
