"""``headsim estimate``: the shipped recording (the simulated paper head, under a robot's
topic and joint names) estimated offline and scored against the truth beside it."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from headsim.cli import main
from headsim.codec import keys
from headsim.head.offline import estimate_file
from headsim.runs.serialise import (
    MEASUREMENT_KEYS,
    RESULTS_SCHEMA,
    EstimateDocument,
    ResultsDocument,
)

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "examples" / "recording"


def _estimate(tmp_path: Path, *extra: str) -> list[str]:
    return [
        "estimate",
        str(SAMPLE / "markers.mcap"),
        "--mapping",
        str(SAMPLE / "mapping.toml"),
        "--out",
        str(tmp_path / "out"),
        *extra,
    ]


@pytest.mark.e2e
def test_the_shipped_recording_is_estimated_and_scored(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (SAMPLE / "markers.mcap").stat().st_size < 1_000_000
    assert main(_estimate(tmp_path, "--truth", str(SAMPLE / "truth.json"))) == 0
    document = json.loads((tmp_path / "out" / "results.json").read_text())
    assert document["status"] == "ok" and document["stereo_pairs"] == 4
    # the run's schema: its keys where a recording has them, its measurement entries
    assert document["schema"] == RESULTS_SCHEMA
    assert tuple(document) == keys(EstimateDocument)
    assert [k for k in keys(ResultsDocument) if k in document] == [
        k for k in document if k in keys(ResultsDocument)
    ]
    assert set(document["summary"]) == {"calibrated"}
    names = [m["name"] for m in document["measurements"]]
    assert names == ["marker_red", "marker_green", "marker_blue"]
    for m in document["measurements"]:
        assert list(m) == list(MEASUREMENT_KEYS)
        assert m["method"] == "stereo_triangulation" and m["details"]["pairs"] == 4
        # the paper's cameras, no noise, a calibration exact to the mount yaws: sub-mm
        assert m["error_m"] < 0.0005, m
    assert "error" in capsys.readouterr().out


@pytest.mark.render
def test_the_shipped_recording_is_what_the_tool_makes(tmp_path: Path) -> None:
    spec = importlib.util.spec_from_file_location("sample", ROOT / "tools" / "sample_recording.py")
    assert spec is not None and spec.loader is not None
    sample = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sample)
    made = sample.make(tmp_path / "made")
    assert (made / "mapping.toml").read_text() == (SAMPLE / "mapping.toml").read_text()
    assert (made / "truth.json").read_text() == (SAMPLE / "truth.json").read_text()
    _, ours, _ = estimate_file(made / "markers.mcap", made / "mapping.toml")
    _, shipped, _ = estimate_file(SAMPLE / "markers.mcap", SAMPLE / "mapping.toml")
    assert [(e.name, e.point_head_m.tolist(), e.pairs) for e in ours] == [
        (e.name, e.point_head_m.tolist(), e.pairs) for e in shipped
    ]


@pytest.mark.fast
@pytest.mark.parametrize(
    "edit, message",
    [
        (("[targets]", "[target]"), "unknown table [target]"),
        (
            ('marker_blue = "blue"', 'marker_blue = "teal"'),
            "targets.marker_blue must be a marker colour",
        ),
        (("baseline_m = 0.15", "baseline_m = 0.15\nbaseline = 1"), "unknown key head.baseline"),
        (('eye = "eyes_verge"', 'eye = "l_eye"'), "has no joint 'l_eye'"),
        (
            ('"/left/image_raw", "/right/image_raw"', '"/left/image_raw"'),
            "topics.images must be a list of two",
        ),
    ],
)
def test_a_bad_mapping_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: tuple[str, str], message: str
) -> None:
    mapping = tmp_path / "mapping.toml"
    mapping.write_text((SAMPLE / "mapping.toml").read_text().replace(*edit))
    command = ["estimate", str(SAMPLE / "markers.mcap"), "--mapping", str(mapping)]
    assert main([*command, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.fast
def test_a_missing_recording_is_bad_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    command = ["estimate", str(tmp_path / "none.mcap"), "--mapping", str(SAMPLE / "mapping.toml")]
    assert main([*command, "--out", str(tmp_path / "out")]) == 2
    assert "no recording" in capsys.readouterr().err
