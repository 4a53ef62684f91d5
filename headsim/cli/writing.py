"""Writing a command's result files: atomically, a full disk reported as such (exit 3).

Also the Rerun recording's end: whether a writer error is a full disk
(:func:`recording_failed`) and closing it (:func:`close_recorder`).
Imports only the standard library and :mod:`headsim.errors` at the top.
"""

from __future__ import annotations

from pathlib import Path

from headsim.errors import (
    NO_SPACE_ERRNOS,
    OutputNotWritable,
)


def file_size(path: Path) -> str:
    size = path.stat().st_size
    return f"{size / 1e6:.1f} MB" if size >= 1e5 else f"{size / 1e3:.0f} kB"


def write_all(files: dict[Path, object]) -> None:
    """Write the result files atomically; on a full disk remove the ones this call wrote."""
    from headsim.files import write_json_atomic, write_text_atomic
    from headsim.runs.outputs import disk_full

    written: list[Path] = []
    for path, content in files.items():
        data = content if isinstance(content, str) else None
        try:
            if data is not None:
                write_text_atomic(path, data)
            else:
                write_json_atomic(path, content)
        except OSError as err:
            for done in written:
                done.unlink(missing_ok=True)
            if err.errno in NO_SPACE_ERRNOS:
                size = len(data.encode()) if data is not None else json_size(content)
                raise disk_full(path, size, err) from err
            raise OutputNotWritable(f"cannot write {path}: {err.strerror or err}") from err
        written.append(path)


def json_size(payload: object) -> int:
    import json

    from headsim.files import to_jsonable

    return len(json.dumps(to_jsonable(payload), indent=2).encode()) + 1


#: What Rerun's file writer says when a write found no space (ENOSPC, EFBIG).
_NO_SPACE_TEXTS = ("os error 28", "os error 27", "no space left", "file too large", "file-writer")


def recording_failed(err: BaseException) -> bool:
    """Whether ``err`` is Rerun's file writer giving up for lack of space (or the size limit)."""
    if isinstance(err, OSError):
        return err.errno in NO_SPACE_ERRNOS
    text = f"{err} {err.__cause__ or ''}".lower()
    return isinstance(err, RuntimeError) and any(t in text for t in _NO_SPACE_TEXTS)


def recording_disk_full(rrd: Path, err: BaseException) -> Exception:
    from headsim.runs.outputs import disk_full

    size = rrd.stat().st_size if rrd.is_file() else None
    return disk_full(rrd, None, err if isinstance(err, OSError) else None, written_bytes=size)


def close_recorder(recorder, rrd: Path | None) -> None:
    """Close the recording as far as Rerun allows; a writer that already died is no new error."""
    try:
        recorder.close()
    except Exception as err:  # the file writer already failed: reported by the caller
        if rrd is not None and recording_failed(err):
            raise recording_disk_full(rrd, err) from err
        raise
