"""Rows a recording logs with every image (poses, joint angles), gathered per entity and
sent as columns: one ``send_columns`` call per entity instead of one ``log`` per row.

``rr.log`` costs about 0.1 ms per Transform3D here, and every image logged a dozen of
them: half a second of the quick start.  The rows are the same (frame and step, the
values), so a viewer shows the same recording.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import rerun as rr


@dataclass
class _Entity:
    """One entity's rows: ``instances`` values of each field per row (None: a list of
    any length per row)."""

    archetype: Any
    instances: int | None
    frames: list[int] = field(default_factory=list)
    lengths: list[int] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)
    fields: dict[str, list[Any]] = field(default_factory=dict)
    #: Fields with one value per row whatever ``instances`` is (e.g. ``show_labels``).
    per_row: dict[str, list[Any]] = field(default_factory=dict)


class RowColumns:
    """Rows kept per entity path until :meth:`send`."""

    def __init__(self) -> None:
        self._entities: dict[str, _Entity] = {}

    def add(
        self,
        path: str,
        frame: int,
        step: int,
        archetype: Any,
        instances: int | None = 1,
        per_row: dict[str, Any] | None = None,
        **values: Any,
    ) -> None:
        """A row of ``archetype`` (``rr.Transform3D``, ``rr.Scalars``, ...) at ``path``:
        ``values`` are the archetype's fields, ``instances`` values each (1: the value
        itself; None: lists of one length, which may be 0: nothing at this row)."""
        entity = self._entities.setdefault(path, _Entity(archetype, instances))
        if entity.archetype is not archetype or entity.instances != instances:
            raise ValueError(f"{path}: rows of one archetype and instance count only")
        if instances != 1:
            lengths = {len(v) for v in values.values()}
            if len(lengths) > 1 or (instances is not None and lengths != {instances}):
                raise ValueError(f"{path}: every field needs {instances or 'the same'} values")
            entity.lengths.append(lengths.pop() if lengths else 0)
        entity.frames.append(frame)
        entity.steps.append(step)
        for name, value in values.items():
            entity.fields.setdefault(name, []).append(value)
        for name, value in (per_row or {}).items():
            entity.per_row.setdefault(name, []).append(value)

    def __len__(self) -> int:
        return sum(len(e.frames) for e in self._entities.values())

    def send(self, rec: rr.RecordingStream) -> None:
        """Send every kept row, an entity per call, and forget them."""
        for path, entity in self._entities.items():
            rows = len(entity.frames)
            if rows == 0:
                continue
            columns = entity.archetype.columns(
                **{name: _column(v, entity.instances) for name, v in entity.fields.items()}
            )
            if entity.instances != 1:
                columns = columns.partition(entity.lengths)
            extra = entity.archetype.columns(**entity.per_row) if entity.per_row else []
            rec.send_columns(
                path,
                indexes=[
                    rr.TimeColumn("frame", sequence=entity.frames),
                    rr.TimeColumn("step", sequence=entity.steps),
                ],
                columns=[*columns, *extra],
            )
        self._entities.clear()


def _column(rows: list[Any], instances: int | None) -> Any:
    """The rows' values end to end: an array, or a list of strings (labels)."""
    flat = list(rows) if instances == 1 else [v for row in rows for v in row]
    return flat if not flat or isinstance(flat[0], str) else np.asarray(flat)


__all__ = ["RowColumns"]
