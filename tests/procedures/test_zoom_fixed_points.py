"""The zoom fixed points through ``headsim run``: each camera's fixed point from real
renders beside the simulator's principal point, the study's helper, and bad keys."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from headsim.cli import main
from headsim.errors import ExitCode
from headsim.sim.settings import paper_head
from headsim.studies.scenario_runs import zoom_fixed_points_run

SCENARIO = """description = "the paper head's zoom fixed points"
seed = 0

[head]
preset = "paper"

[experiment]
procedure = "zoom_fixed_points"

[experiment.zoom_fixed_points]
{line}
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """Two board poses on the paper head, run once: the output folder and recording."""
    root = tmp_path_factory.mktemp("zoom")
    path, out, rrd = root / "zoom.toml", root / "out", root / "zoom.rrd"
    path.write_text(SCENARIO.format(line="poses = 2"))
    argv = ["run", str(path), "--out", str(out), "--rrd", str(rrd), "--no-progress"]
    assert main(argv) == 0
    return out, rrd


def test_each_fixed_point_lies_near_the_principal_point(run: tuple[Path, Path]) -> None:
    results = json.loads((run[0] / "results.json").read_text())
    block = results["experiment"]
    assert results["status"] == "ok" and block["procedure"] == "zoom_fixed_points"
    assert block["zoom"] == pytest.approx(1.3) and block["views"] == 2
    assert block["renders"] == 2 * 2 * 2  # two poses, two cameras, two focal lengths
    truth = [list(c.principal) for c in paper_head().cameras]
    assert block["truth_px"] == truth
    error = np.array(block["fixed_point_px"]) - np.array(truth)
    assert np.allclose(error, block["error_px"])
    assert np.abs(error).max() < 1.0  # px: the paper's principal points are off-centre
    assert all(s == pytest.approx(1.3, abs=0.01) for s in block["scale"])


def test_the_recording_holds_each_fixed_point(run: tuple[Path, Path]) -> None:
    block = json.loads((run[0] / "results.json").read_text())["experiment"]
    for k, cam in enumerate(("cam1", "cam2")):
        entity = f"/world/head/{cam}/zoom_fixed_point"
        points = [
            row
            for chunk in RrdReader(run[1]).stream().filter(content=entity)
            for row in chunk.to_record_batch().column("Points2D:positions").to_pylist()
        ]
        assert np.allclose(np.array(points[0]), [block["fixed_point_px"][k]], atol=1e-3)


def test_the_study_helper_gives_the_runs_fixed_points(run: tuple[Path, Path]) -> None:
    block = json.loads((run[0] / "results.json").read_text())["experiment"]
    found = zoom_fixed_points_run(paper_head(seed=0), 1.3, 2, board_seed=0)
    assert np.allclose(found.principal_px, block["fixed_point_px"])
    assert found.renders == block["renders"]


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("zoom = 1.0", "experiment.zoom_fixed_points.zoom: 1 is out of range"),
        ("poses = 0", "experiment.zoom_fixed_points.poses: 0 is out of range"),
        ("board_seed = -1", "experiment.zoom_fixed_points.board_seed: -1 is out of range"),
        ("board_seed = 1.5", "experiment.zoom_fixed_points.board_seed: must be an integer"),
        ("focal = 2", "experiment.zoom_fixed_points.focal: unknown key"),
    ],
)
def test_a_bad_zoom_key_is_one_line_naming_it(
    line: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "zoom.toml"
    path.write_text(SCENARIO.format(line=line))
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == ExitCode.BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "out").exists()
