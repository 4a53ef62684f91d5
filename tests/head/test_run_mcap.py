"""``headsim run ... --mcap FILE``: the run's images, cameras, joints, TF, commands and
estimates as ROS 2 messages, with results.json as without it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from mcap.reader import make_reader

from headsim.cli import main
from headsim.head.mcap_log import read_log

pytestmark = pytest.mark.e2e


def test_a_run_records_to_mcap_and_its_results_do_not_move(tmp_path: Path) -> None:
    plain, recorded = tmp_path / "plain", tmp_path / "recorded"
    mcap = recorded / "run.mcap"
    assert main(["run", "quickstart", "--fast", "--out", str(plain), "--no-progress"]) == 0
    command = ["run", "quickstart", "--fast", "--out", str(recorded), "--mcap", str(mcap)]
    assert main([*command, "--no-progress"]) == 0
    assert (plain / "results.json").read_bytes() == (recorded / "results.json").read_bytes()
    with mcap.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None
    counts = {
        summary.channels[cid].topic: n
        for cid, n in summary.statistics.channel_message_counts.items()
    }
    assert counts["/cam1/image_raw"] > 0 and counts["/cam2/image_raw"] > 0
    assert counts["/cam1/camera_info"] == counts["/cam1/image_raw"]
    assert (
        counts["/joint_states"]
        == counts["/tf"]
        == counts["/cam1/image_raw"] + counts["/cam2/image_raw"]
    )
    assert counts["/headsim/estimates"] == 3  # the fast quick start's three markers
    log = read_log(mcap)
    measured = json.loads((recorded / "results.json").read_text())["measurements"]
    assert [(n, p.tolist()) for n, _, p in log.estimates] == [
        (m["name"], m["estimate_head_m"]) for m in measured
    ]
    assert log.joints.names == ("neck_yaw", "neck_pitch", "eye")


def test_mcap_into_a_directory_is_bad_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    command = ["run", "quickstart", "--fast", "--out", str(tmp_path / "o"), "--mcap", str(tmp_path)]
    assert main(command) == 2
    err = capsys.readouterr().err
    assert "--mcap" in err and "is a directory" in err and "Traceback" not in err
