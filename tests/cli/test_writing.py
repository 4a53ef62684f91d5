"""Writing a command's result files on a real file system; Rerun's writer errors classified."""

from __future__ import annotations

import errno
import json
from pathlib import Path

import pytest

from headsim.cli.writing import (
    file_size,
    json_size,
    recording_disk_full,
    recording_failed,
    write_all,
)
from headsim.errors import DiskFull, OutputNotWritable


def test_result_files_are_written_and_the_json_size_is_exact(tmp_path: Path) -> None:
    payload = {"scenario": "quickstart", "wall_s": 1.5, "phases_s": {"run": 1.0}, "rrd": None}
    write_all({tmp_path / "summary.txt": "ok\n", tmp_path / "timing.json": payload})
    assert (tmp_path / "summary.txt").read_text() == "ok\n"
    assert json.loads((tmp_path / "timing.json").read_text()) == payload
    # The size a full disk's message names is the size the file takes.
    assert json_size(payload) == (tmp_path / "timing.json").stat().st_size
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.txt", "timing.json"]


def test_a_failed_write_removes_the_files_written_before_it(tmp_path: Path) -> None:
    blocker = tmp_path / "blocker"
    blocker.write_text("")  # a file where the second one's directory would be
    first, second = tmp_path / "results.json", blocker / "summary.txt"
    with pytest.raises(OutputNotWritable, match=f"cannot write {second}: "):
        write_all({first: {"a": 1}, second: "text"})
    assert not first.exists()


def test_rerun_writer_errors_for_lack_of_space_are_told_apart() -> None:
    assert recording_failed(OSError(errno.ENOSPC, "No space left on device"))
    assert recording_failed(OSError(errno.EFBIG, "File too large"))
    assert not recording_failed(OSError(errno.EACCES, "Permission denied"))
    assert recording_failed(RuntimeError("file-writer: I/O error (os error 28)"))
    assert not recording_failed(RuntimeError("viewer closed the connection"))
    assert not recording_failed(ValueError("no space left"))  # not the writer's kind


def test_a_recording_that_ran_out_of_space_names_the_file_and_its_size(tmp_path: Path) -> None:
    rrd = tmp_path / "run.rrd"
    rrd.write_bytes(b"\0" * 150_000)
    error = recording_disk_full(rrd, RuntimeError("os error 28"))
    assert isinstance(error, DiskFull)
    assert str(error).startswith(f"no space to write {rrd} after 150.0 kB: ")
    assert file_size(rrd) == "0.1 MB"
    rrd.write_bytes(b"\0" * 2_000)
    assert file_size(rrd) == "2 kB"
