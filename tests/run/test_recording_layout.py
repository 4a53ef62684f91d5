"""The recording's layout, read back from the file: one document per text view, the 3-D
view's eye; the calibration's document."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import replace
from pathlib import Path

import numpy as np
from rerun.chunk import RrdReader

from headsim.active.calibration_report import CalibrationReport
from headsim.estimators.result import Status
from headsim.runs.recording_layout import calibration_markdown
from headsim.sim.events import RenderCounts


def _blueprint_views(path: Path) -> dict[str, dict[str, object]]:
    """The layout stored in the file: view id -> class, origin and content query."""
    reader = RrdReader(path)
    views: dict[str, dict[str, object]] = defaultdict(dict)
    for chunk in reader.stream(store=reader.blueprints()[0]):
        if not chunk.entity_path.startswith("/view/"):
            continue
        batch = chunk.to_record_batch()
        view = chunk.entity_path.split("/")[2]
        for column, key in (
            ("ViewBlueprint:class_identifier", "class"),
            ("ViewBlueprint:space_origin", "origin"),
            ("ViewContents:query", "query"),
        ):
            if column in batch.schema.names:
                views[view][key] = batch.column(column).to_pylist()[-1]
    return views


def _query_matches(query: list[str], origin: str, path: str) -> bool:
    """Rerun's entity path filter: the most specific matching rule (+ or -) decides."""
    best: tuple[int, bool] | None = None
    for rule in query:
        rule = rule.strip()
        include = not rule.startswith("-")  # "+" is optional
        pattern = rule[1:] if rule[:1] in "+-" else rule
        pattern = pattern.strip().replace("$origin", origin.rstrip("/") or "/")
        if pattern.endswith("/**"):
            base = pattern[:-3] or "/"
            hit = path == base or path.startswith(base.rstrip("/") + "/")
            specificity = 2 * base.count("/")
        else:
            hit, specificity = path == pattern, 2 * pattern.count("/") + 1
        if hit and (best is None or specificity >= best[0]):
            best = (specificity, include)
    return best is not None and best[1]


def test_each_text_view_of_the_layout_shows_exactly_one_document(
    recorded: tuple[Path, dict],
) -> None:
    rrd, _ = recorded
    documents = {
        chunk.entity_path
        for chunk in RrdReader(rrd).stream().filter(components="TextDocument:text")
    }
    assert documents == {
        "/results/scenario",
        "/results/calibration",
        "/results/summary",
        "/results/measurements",
    }
    views = _blueprint_views(rrd)
    text_views = [v for v in views.values() if v.get("class") == ["TextDocument"]]
    assert len(text_views) == len(documents)
    shown = []
    for view in text_views:
        origin = view["origin"][0]
        matched = [d for d in documents if _query_matches(view["query"], origin, d)]
        assert len(matched) == 1, (origin, view["query"], matched)
        shown += matched
    assert sorted(shown) == sorted(documents)  # and every document has its view
    # The old layout (one view of /results) would have failed here.
    assert len([d for d in documents if _query_matches(["+ $origin/**"], "/results", d)]) == 4


def test_the_3d_view_starts_behind_and_above_the_head(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    reader = RrdReader(rrd)
    eye = {}
    for chunk in reader.stream(store=reader.blueprints()[0]):
        if chunk.entity_path.endswith("/EyeControls3D"):
            batch = chunk.to_record_batch()
            eye = {n: batch.column(n).to_pylist()[-1] for n in batch.schema.names if ":" in n}
    position = np.array(eye["EyeControls3D:position"][0])
    target = np.array(eye["EyeControls3D:look_target"][0])
    head = np.array([0.0, 0.0, 0.21])
    assert position[1] < head[1] - 0.2 and position[2] > head[2] + 0.2  # behind, above
    assert eye["EyeControls3D:eye_up"][0] == [0.0, 0.0, 1.0]  # W's up axis
    # Looking forward, between the head and the targets.
    farthest = max(m["truth_world_m"][1] for m in results["measurements"])
    assert head[1] < target[1] < farthest


def test_the_calibration_document_reads_the_report() -> None:
    failed = CalibrationReport(
        Status.FAILED, "failed: too few positions seen", 8, 2, RenderCounts(images=30)
    )
    assert calibration_markdown(failed) == "# Calibration\n\nfailed: too few positions seen\n"
    ok = replace(
        failed,
        status=Status.OK,
        detail="",
        fixated=8,
        alpha_e_rad=[0.05812, -0.02531],
        alpha_e_truth_rad=[0.0578, -0.0254],
        alpha_e_paper_rad=[0.0578, -0.0254],
    )
    text = calibration_markdown(ok)
    assert "8 of 8 positions fixated, 30 renders" in text
    assert "| alpha_e1 | 0.05812 | 0.05780 | 0.0578 |" in text and "extended" not in text
