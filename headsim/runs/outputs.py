"""Output files checked before a run, and cleaned up after one that wrote nothing.

A command that writes files creates one :class:`Outputs`, declares every file
it will write (``outputs.directory(...)``, ``outputs.file(...)``) before it
renders anything, and removes the directories it created if they stayed empty::

    outputs = Outputs()
    out_dir = outputs.directory(args.out, "--out")
    outputs.file(out_dir / "results.json", "--out")   # atomic: tmp file + rename
    outputs.file(args.rrd, "--rrd", atomic=False)      # written in place
    try:
        ...
    finally:
        outputs.remove_empty_created()

Problems become :class:`~headsim.errors.BadInput` (a path that cannot be one,
e.g. a directory given as a file) or :class:`~headsim.errors.OutputNotWritable`
(permissions, a read-only file system), each naming the option and the path.
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from pathlib import Path

from headsim.errors import BadInput, DiskFull, OutputNotWritable


def _reason(err: OSError) -> str:
    return err.strerror or str(err)


class Outputs:
    """The directories and files one command writes; remembers which directories it created."""

    def __init__(self) -> None:
        self.created: list[Path] = []

    def _make_dirs(self, directory: Path, option: str) -> None:
        missing: list[Path] = []
        probe = directory
        while not probe.exists():
            if probe.is_symlink():  # a dangling link: mkdir would fail on it
                break
            missing.append(probe)
            if probe.parent == probe:
                break
            probe = probe.parent
        if probe.exists() and not probe.is_dir():
            raise BadInput(f"{option}: {probe} exists and is not a directory")
        for path in reversed(missing):
            try:
                path.mkdir()
            except FileExistsError:
                continue
            except OSError as err:
                raise OutputNotWritable(
                    f"{option}: cannot create the directory {path}: {_reason(err)}"
                ) from err
            self.created.append(path)

    def directory(self, path: str | Path, option: str) -> Path:
        """Check (and create) an output directory; refuse a file or an unwritable place."""
        directory = Path(path)
        if directory.exists() and not directory.is_dir():
            raise BadInput(f"{option}: {directory} exists and is not a directory")
        self._make_dirs(directory, option)
        self._probe_directory(directory, option)
        return directory

    def _probe_directory(self, directory: Path, option: str) -> None:
        try:
            fd, tmp = tempfile.mkstemp(dir=directory, prefix=".headsim-probe-")
        except OSError as err:
            raise OutputNotWritable(
                f"{option}: cannot write in {directory}: {_reason(err)}"
            ) from err
        os.close(fd)
        Path(tmp).unlink(missing_ok=True)

    def file(self, path: str | Path, option: str, *, atomic: bool = True) -> Path:
        """Check that ``path`` can be written as a file, as the real file would be.

        ``atomic`` files are written as a temporary file in the same directory and
        renamed over ``path``; other files (the Rerun recording) are opened in place.
        """
        target = Path(path)
        if target.is_dir():
            raise BadInput(f"{option}: {target} is a directory (allowed: a file path)")
        parent = target.parent
        if parent.exists() and not parent.is_dir():
            raise BadInput(f"{option}: {parent} exists and is not a directory")
        self._make_dirs(parent, option)
        if target.exists() and not atomic:
            try:
                with open(target, "ab"):
                    pass
            except OSError as err:
                raise OutputNotWritable(f"{option}: cannot write {target}: {_reason(err)}") from err
            return target
        self._probe_directory(parent, option)
        return target

    def remove_empty_created(self) -> None:
        """Remove the directories this command created, where they are still empty."""
        for directory in reversed(self.created):
            try:
                directory.rmdir()
            except OSError:
                continue


def disk_full(
    path: str | Path,
    needed_bytes: int | None,
    err: OSError | None = None,
    written_bytes: int | None = None,
) -> DiskFull:
    """A :class:`DiskFull` naming the file, what it needed and what is free (or the size limit)."""
    target = Path(path)
    limit = file_size_limit()
    needed = f"{_bytes(needed_bytes)} needed; " if needed_bytes is not None else ""
    written = f" after {_bytes(written_bytes)}" if written_bytes is not None else ""
    over_limit = limit is not None and (
        (err is not None and err.errno == errno.EFBIG)
        or (err is None and written_bytes is not None and written_bytes >= limit)
    )
    if over_limit:
        cause = f"the file-size limit (ulimit -f) of {_bytes(limit)} was reached"
    else:
        cause = f"{_bytes(_free_bytes(target))} free on its file system"
    return DiskFull(
        f"no space to write {target}{written}: {needed}{cause}; free some space or write elsewhere"
    )


def file_size_limit() -> int | None:
    """The process's file-size limit (``ulimit -f``) in bytes, None when unlimited."""
    try:
        import resource
    except ImportError:  # not on POSIX
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    return None if soft == resource.RLIM_INFINITY else int(soft)


def _free_bytes(path: Path) -> int | None:
    probe = path if path.is_dir() else path.parent
    try:
        return shutil.disk_usage(probe).free
    except OSError:
        return None


def _bytes(count: int | None) -> str:
    if count is None:
        return "an unknown amount"
    if count >= 1e6:
        return f"{count / 1e6:.1f} MB"
    if count >= 1e3:
        return f"{count / 1e3:.1f} kB"
    return f"{count} bytes"
