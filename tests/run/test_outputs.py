"""Output checks before a run, on real directories and files (and a read-only file system)."""

from __future__ import annotations

import errno
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from headsim.errors import BadInput, DiskFull, OutputNotWritable
from headsim.runs.outputs import Outputs, disk_full, file_size_limit


def read_only_dir(tmp_path: Path) -> Path:
    """A directory no file can be created in (as root, where permission bits do not apply,
    /proc/sys: procfs takes no new files)."""
    if os.geteuid() == 0:
        path = Path("/proc/sys")
    else:
        path = tmp_path / "read-only"
        path.mkdir()
        path.chmod(0o555)
    with pytest.raises(OSError):  # the premise
        tempfile.mkstemp(dir=path)
    return path


def test_a_directory_is_created_checked_and_removed_again_when_empty(tmp_path: Path) -> None:
    outputs = Outputs()
    out = outputs.directory(tmp_path / "a" / "b" / "c", "--out")
    assert out.is_dir()
    assert outputs.created == [tmp_path / "a", tmp_path / "a" / "b", out]
    assert list(out.iterdir()) == []  # the write probe left nothing
    (tmp_path / "a" / "b" / "kept.txt").write_text("x")
    outputs.remove_empty_created()
    assert not out.exists()
    assert (tmp_path / "a" / "b" / "kept.txt").exists()  # b and a hold a file: they stay


def test_a_file_where_a_directory_belongs_names_the_option(tmp_path: Path) -> None:
    blocker = tmp_path / "results"
    blocker.write_text("")
    with pytest.raises(BadInput, match=f"--out: {blocker} exists and is not a directory"):
        Outputs().directory(blocker, "--out")
    with pytest.raises(BadInput, match=f"--out: {blocker} exists and is not a directory"):
        Outputs().directory(blocker / "deeper", "--out")
    with pytest.raises(BadInput, match=f"--json: {tmp_path} is a directory \\(allowed: a file"):
        Outputs().file(tmp_path, "--json")
    with pytest.raises(BadInput, match=f"--json: {blocker} exists and is not a directory"):
        Outputs().file(blocker / "m.json", "--json")


def test_a_file_is_checked_as_it_will_be_written(tmp_path: Path) -> None:
    outputs = Outputs()
    target = outputs.file(tmp_path / "new" / "m.json", "--json")
    assert target.parent.is_dir() and not target.exists()
    assert outputs.created == [tmp_path / "new"]
    existing = tmp_path / "run.rrd"
    existing.write_bytes(b"kept")
    assert outputs.file(existing, "--rrd", atomic=False) == existing
    assert existing.read_bytes() == b"kept"  # opened for appending, not truncated


def test_an_unwritable_place_is_refused_before_anything_runs(tmp_path: Path) -> None:
    place = read_only_dir(tmp_path)
    with pytest.raises(OutputNotWritable, match=f"--out: cannot write in {place}: "):
        Outputs().directory(place, "--out")
    with pytest.raises(OutputNotWritable, match=f"--out: cannot create the directory {place}/x"):
        Outputs().directory(place / "x", "--out")
    with pytest.raises(OutputNotWritable, match=f"--json: cannot write in {place}"):
        Outputs().file(place / "m.json", "--json")


def test_a_full_disk_names_the_file_what_it_needed_and_what_is_free(tmp_path: Path) -> None:
    error = disk_full(tmp_path / "results.json", 2_500, OSError(errno.ENOSPC, "full"))
    assert isinstance(error, DiskFull)
    assert str(error).startswith(f"no space to write {tmp_path / 'results.json'}: 2.5 kB needed; ")
    assert str(error).endswith(" free on its file system; free some space or write elsewhere")
    after = disk_full(tmp_path / "r.rrd", None, written_bytes=1_200_000)
    assert str(after).startswith(f"no space to write {tmp_path / 'r.rrd'} after 1.2 MB: ")


def test_the_file_size_limit_is_read_and_named() -> None:
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    assert file_size_limit() == (None if soft == resource.RLIM_INFINITY else soft)
    code = (
        "import errno; from headsim.runs.outputs import disk_full, file_size_limit; "
        "print(file_size_limit()); "
        "print(disk_full('/tmp/x.json', 120, OSError(errno.EFBIG, 'too large')))"
    )

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))

    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, preexec_fn=limit
    )
    lines = result.stdout.splitlines()
    assert lines[0] == "100000", result.stderr
    assert lines[1] == (
        "no space to write /tmp/x.json: 120 bytes needed; the file-size limit (ulimit -f) "
        "of 100.0 kB was reached; free some space or write elsewhere"
    )
