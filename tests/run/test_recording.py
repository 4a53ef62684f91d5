"""The Rerun recording, read back with ``rerun.chunk.RrdReader``: the documented entities at their steps."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

from rerun.chunk import RrdReader

from .rrd import rows

README = Path(__file__).resolve().parents[2] / "README.md"
ROOT = README.parent


def test_the_file_is_complete_with_its_blueprint(recorded: tuple[Path, dict]) -> None:
    rrd, _ = recorded
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a file without footer would warn
        reader = RrdReader(rrd)
        assert [r.recording_id for r in reader.recordings()] == ["quickstart-fast-seed0"]
        assert len(reader.blueprints()) == 1


def _rows_per_entity(rrd: Path) -> dict[str, int]:
    counts: dict[str, int] = defaultdict(int)
    for chunk in RrdReader(rrd).stream():
        counts[chunk.entity_path] += chunk.to_record_batch().num_rows
    return dict(counts)


def test_the_command_line_leaves_only_once_the_recording_is_complete(
    recorded: tuple[Path, dict], tmp_path: Path
) -> None:
    # The process's own entry point: the recording it wrote has its footer and every
    # row of a run in-process.
    out, rrd = tmp_path / "out", tmp_path / "run.rrd"
    command = [sys.executable, "-m", "headsim.cli", "run", "quickstart", "--fast"]
    command += ["--out", str(out), "--rrd", str(rrd), "--no-progress"]
    done = subprocess.run(
        command, capture_output=True, text=True, timeout=300, check=False,
        env={**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "recording" in done.stdout  # stdout was flushed before leaving
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a file without footer would warn
        assert len(RrdReader(rrd).blueprints()) == 1
    assert _rows_per_entity(rrd) == _rows_per_entity(recorded[0])
    assert (out / "results.json").read_text() == (recorded[0].parent / "results.json").read_text()


def test_every_recorded_entity_is_documented(recorded: tuple[Path, dict]) -> None:
    rrd, _ = recorded
    text = README.read_text()
    table = text[text.index("| entity | type | what |") :].split("\n\n")[0]
    documented = set()
    for cell in re.findall(r"^\| ([^|]+) \|", table, re.M):
        paths = re.findall(r"`([^`]+)`", cell)
        if not paths:
            continue
        base = paths[0]
        for p in paths:
            documented.add(base.rsplit("/", 2)[0] + p[3:] if p.startswith("...") else p)
    recorded_entities = {
        chunk.entity_path
        for chunk in RrdReader(rrd).stream()
        if not chunk.entity_path.startswith("/__")
    }
    # The model's bodies and geoms: one README row stands for them (tests/run/test_mjcf_rerun.py).
    assert "`/world/model/BODY`" in table
    recorded_entities = {e for e in recorded_entities if not e.startswith("/world/model/")}
    assert recorded_entities <= documented, recorded_entities - documented


def test_an_interrupted_run_leaves_a_readable_recording_and_no_results(tmp_path: Path) -> None:
    out, rrd = tmp_path / "out", tmp_path / "run.rrd"
    command = [
        sys.executable,
        "-m",
        "headsim.cli",
        "run",
        "chessboard",
        "--out",
        str(out),
        "--rrd",
        str(rrd),
    ]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        command, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        deadline = time.monotonic() + 60
        # Wait for the first flushed measurements (a few hundred kB of images).
        while time.monotonic() < deadline and (not rrd.exists() or rrd.stat().st_size < 300_000):
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.1)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "interrupted: nothing written to" in err
    assert not (out / "results.json").exists()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # closed with its footer
        reader = RrdReader(rrd)
        assert len(reader.recordings()) == 1
    images = rows(rrd, "/world/head/cam1/image", "EncodedImage:blob")
    assert len(images) > 5
    counts: dict[str, int] = defaultdict(int)
    for chunk in RrdReader(rrd).stream():
        counts[chunk.entity_path] += 1
    assert counts["/world/head"] > 0
