"""The summary table's cells and columns, for people: shared by the runner's summary
and each procedure's own lines (:mod:`headsim.procedures`)."""

from __future__ import annotations

import math
from typing import Any


def cell(value: Any, fmt: str = "") -> str:
    """``value`` formatted, or "-" for None and non-finite floats."""
    if value is None:
        return "-"
    if isinstance(value, float):
        return "-" if not math.isfinite(value) else format(value, fmt)
    return str(value)


def mm(value_m: float | None, fmt: str = ".2f") -> str:
    """A length given in m, shown in mm."""
    return cell(None if value_m is None else value_m * 1000.0, fmt)


def format_table(headers: list[str], rows: list[list[str]], indent: str = "  ") -> list[str]:
    """Columns padded to their widest cell; the first column left, the others right."""
    widths = [max(len(str(c)) for c in column) for column in zip(headers, *rows, strict=True)]

    def line(cells: list[str]) -> str:
        parts = [
            str(c).ljust(w) if k == 0 else str(c).rjust(w)
            for k, (c, w) in enumerate(zip(cells, widths, strict=True))
        ]
        return (indent + "  ".join(parts)).rstrip()

    return [line(headers), *(line(r) for r in rows)]


__all__ = ["cell", "format_table", "mm"]
