"""The campaigns' one writer: a campaign's rows as ``<stem>.csv``, its document (the rows
and what describes them) as ``<stem>.json``, and its figure as ``<stem>.png``."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from headsim.files import write_csv_atomic, write_json_atomic


def write_rows(
    out: Path,
    stem: str,
    rows: Sequence[dict[str, Any]],
    document: dict[str, Any],
    draw: Callable[[Path], Any] | None = None,
) -> dict[str, Path]:
    """Write ``rows`` to ``out/<stem>.csv`` and ``document`` to ``out/<stem>.json``; with
    ``draw``, ``draw(out/<stem>.png)`` draws the figure.  The paths by kind: csv, json, png."""
    files = {
        "csv": write_csv_atomic(out / f"{stem}.csv", list(rows)),
        "json": write_json_atomic(out / f"{stem}.json", document),
    }
    if draw is not None:
        files["png"] = out / f"{stem}.png"
        draw(files["png"])
    return files
