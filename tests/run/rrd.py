"""Reading a recording back: one component of one entity, row by row."""

from __future__ import annotations

from pathlib import Path

from rerun.chunk import RrdReader


def rows(path: Path, entity: str, component: str) -> list[dict[str, object]]:
    """Rows of one component of one entity: frame, step (None when static) and the value."""
    rows = []
    for chunk in RrdReader(path).stream().filter(content=entity, components=component):
        batch = chunk.to_record_batch()
        names = batch.schema.names
        frames = batch.column("frame").to_pylist() if "frame" in names else [None] * batch.num_rows
        steps = batch.column("step").to_pylist() if "step" in names else [None] * batch.num_rows
        values = batch.column(component).to_pylist()
        rows += [
            {"frame": f, "step": s, "value": v}
            for f, s, v in zip(frames, steps, values, strict=True)
        ]
    return sorted(rows, key=lambda r: (r["frame"] is not None, r["frame"] or 0))
