"""Rerun's command-line options (--rrd, --connect/--url, --serve) for commands that record."""

from __future__ import annotations

import argparse
import json
import subprocess
import time
import warnings
from pathlib import Path

import pytest
from rerun.chunk import RrdReader

from headsim.cli import main
from headsim.runs.rerun_cli import (
    DEFAULT_URL,
    RecordingArgumentError,
    add_recording_arguments,
    recording_target,
)
from tests.run.viewer.browser import free_port, rerun_executable, wait_for_port


def _target(*argv: str):
    parser = argparse.ArgumentParser()
    add_recording_arguments(parser)
    return recording_target(parser.parse_args(list(argv)))


def test_options_become_a_target() -> None:
    assert not _target().wanted
    target = _target("--rrd", "x.rrd")
    assert target.rrd == Path("x.rrd") and target.connect_url is None and not target.serve
    assert _target("--connect").connect_url == DEFAULT_URL
    url = "rerun+http://10.0.0.2:9876/proxy"
    assert _target("--connect", "--url", url).connect_url == url
    served = _target("--serve", "--web-port", "8000", "--grpc-port", "8001")
    assert served.wanted and served.server_url == "rerun+http://127.0.0.1:8001/proxy"
    assert served.web_viewer_url == (
        "http://127.0.0.1:8000/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A8001%2Fproxy"
    )


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--url", DEFAULT_URL], "--url: given without --connect"),
        (["--connect", "--url", "http://host:9876"], "--url: 'http://host:9876' is not a Rerun"),
        (["--serve", "--web-port", "0"], "--web-port: 0 is not a port"),
        (["--serve", "--web-port", "9000", "--grpc-port", "9000"], "--web-port: is the same"),
    ],
)
def test_bad_options_are_refused_with_the_field(argv: list[str], message: str) -> None:
    with pytest.raises(RecordingArgumentError, match="allowed:") as caught:
        _target(*argv)
    assert str(caught.value).startswith(message)


def test_run_refuses_a_bad_url_before_running(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    out = tmp_path / "out"
    assert main(["run", "quickstart", "--out", str(out), "--url", DEFAULT_URL]) == 2
    assert "--url: given without --connect" in capsys.readouterr().err
    assert not (out / "results.json").exists()


def test_connect_streams_to_a_viewer_and_still_writes_the_file(tmp_path: Path) -> None:
    port = free_port()
    received = tmp_path / "received.rrd"
    # A real Rerun gRPC server that saves what it receives.
    command = [rerun_executable(), "--port", str(port), "--save", str(received)]
    viewer = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        wait_for_port(port, 60, viewer)
        rrd = tmp_path / "run.rrd"
        url = f"rerun+http://127.0.0.1:{port}/proxy"
        argv = ["run", "quickstart", "--fast", "--out", str(tmp_path), "--rrd", str(rrd)]
        assert main([*argv, "--connect", "--url", url, "--no-progress"]) == 0
        time.sleep(2.0)  # the server writes what it got
    finally:
        viewer.terminate()
        viewer.wait(timeout=60)
    with warnings.catch_warnings():
        # A stopped `rerun --save` leaves its file without footer; headsim's has one.
        warnings.filterwarnings("ignore", message=".*no footer")
        for path in (rrd, received):
            reader = RrdReader(path)
            assert [r.recording_id for r in reader.recordings()] == ["quickstart-fast-seed0"]
            assert len(reader.blueprints()) == 1
        images = {
            p: sum(
                c.num_rows
                for c in RrdReader(p)
                .stream()
                .filter(content="/world/head/cam1/image", components="EncodedImage:blob")
            )
            for p in (rrd, received)
        }
    assert images[rrd] == images[received] > 10  # every image reached the viewer


def test_sweep_records_each_job_to_its_own_file(tmp_path: Path) -> None:
    grid = Path(__file__).resolve().parents[1] / "data" / "sweep_grid.toml"
    rrd_dir = tmp_path / "recordings"
    argv = ["sweep", str(grid), "--out", str(tmp_path / "out"), "--rrd", str(rrd_dir)]
    assert main([*argv, "--no-progress"]) == 0
    jobs = [
        json.loads(line)["id"]
        for line in (tmp_path / "out" / "jobs.jsonl").read_text().splitlines()
    ]
    assert len(jobs) == 4
    assert sorted(p.stem for p in rrd_dir.glob("*.rrd")) == sorted(jobs)
    for job in jobs:
        reader = RrdReader(rrd_dir / f"{job}.rrd")
        assert [r.recording_id for r in reader.recordings()] == [job]
        assert len(reader.blueprints()) == 1


def test_sweep_refuses_serve_and_a_file_as_rrd_dir(tmp_path: Path) -> None:
    grid = Path(__file__).resolve().parents[1] / "data" / "sweep_grid.toml"
    with pytest.raises(SystemExit):  # argparse: sweep has no --serve
        main(["sweep", str(grid), "--out", str(tmp_path), "--serve"])
    not_a_dir = tmp_path / "file.rrd"
    not_a_dir.write_text("")
    assert main(["sweep", str(grid), "--out", str(tmp_path), "--rrd", str(not_a_dir)]) == 2
