"""Rows sent as columns (run/recording_columns.py): written to a real .rrd and read back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from headsim.run.recording_columns import RowColumns
from tests.run.rrd import rows


def test_rows_come_back_with_their_frames_steps_and_values(tmp_path: Path) -> None:
    path = tmp_path / "columns.rrd"
    rec = rr.RecordingStream("headsim_test")
    rec.save(path)
    kept = RowColumns()
    for frame in range(3):
        turn = np.array(
            [
                [1.0, 0.0, 0.0],
                [0.0, np.cos(frame), -np.sin(frame)],
                [0, np.sin(frame), np.cos(frame)],
            ]
        )
        kept.add(
            "/a", frame, frame // 2, rr.Transform3D, translation=[frame, 0.0, 1.0], mat3x3=turn
        )
        kept.add("/s", frame, frame // 2, rr.Scalars, scalars=0.5 * frame)
        kept.add(
            "/arrows",
            frame,
            frame // 2,
            rr.Arrows3D,
            instances=2,
            per_row={"show_labels": False},
            origins=[[0.0, 0.0, frame], [1.0, 0.0, 0.0]],
            vectors=[[1.0, 0.0, 0.0], [0.0, 1.0, frame]],
            labels=["cam1", "cam2"],
        )
    assert len(kept) == 9
    kept.send(rec)
    assert len(kept) == 0
    kept.send(rec)  # nothing kept: nothing sent
    rec.flush()
    rec.disconnect()

    translations = rows(path, "/a", "Transform3D:translation")
    assert [(r["frame"], r["step"]) for r in translations] == [(0, 0), (1, 0), (2, 1)]
    assert [r["value"] for r in translations] == [[[f, 0.0, 1.0]] for f in (0.0, 1.0, 2.0)]
    mats = rows(path, "/a", "Transform3D:mat3x3")
    # Rerun stores 3x3 matrices column-major.
    np.testing.assert_allclose(
        np.reshape(mats[1]["value"][0], (3, 3)).T[1, 1:], [np.cos(1), -np.sin(1)]
    )
    assert [r["value"] for r in rows(path, "/s", "Scalars:scalars")] == [[0.0], [0.5], [1.0]]
    vectors = rows(path, "/arrows", "Arrows3D:vectors")
    assert [len(r["value"]) for r in vectors] == [2, 2, 2]
    assert vectors[2]["value"][1] == [0.0, 1.0, 2.0]
    assert [r["value"] for r in rows(path, "/arrows", "Arrows3D:labels")] == [["cam1", "cam2"]] * 3
    assert [r["value"] for r in rows(path, "/arrows", "Arrows3D:show_labels")] == [[False]] * 3


def test_one_entity_keeps_one_archetype_and_instance_count() -> None:
    kept = RowColumns()
    kept.add("/s", 0, 0, rr.Scalars, scalars=1.0)
    with pytest.raises(ValueError, match="/s"):
        kept.add("/s", 1, 0, rr.Transform3D, translation=[0.0, 0.0, 0.0])
