"""natural_field_markers, natural_field's marker twin, fast through the real command line:
the same drawn points as natural_field for the seed, each measured with the marker put
5 mm out along the surface's normal, found by its colour, scored like the markerless."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from headsim.cli import main
from headsim.runs.surface import MARKER_OFFSET_M, TWIN_MARKER


def _run(name: str, out: Path) -> dict:
    code = main(["run", name, "--fast", "--seed", "1", "--out", str(out), "--no-progress"])
    results = json.loads((out / "results.json").read_text())
    assert code == (0 if results["status"] == "ok" else 1)
    return results


def test_the_twin_measures_natural_fields_points_with_a_marker_at_each(tmp_path: Path) -> None:
    markerless = _run("natural_field", tmp_path / "surface")
    twin = _run("natural_field_markers", tmp_path / "markers")
    assert markerless["scenario"]["scene"]["room"] == twin["scenario"]["scene"]["room"]
    points = markerless["experiment"]["surface_targets"]["targets"]
    assert twin["experiment"]["surface_targets"]["targets"] == points
    assert twin["experiment"]["surface_targets"]["measured_as"] == "markers"
    assert [m["name"] for m in twin["measurements"]] == [p["name"] for p in points]
    for point, m in zip(points, twin["measurements"], strict=True):
        # The marker's centre: 5 mm out from the point (along the normal, toward the eyes).
        off = np.subtract(m["truth_world_m"], point["point_world_m"])
        assert abs(float(np.linalg.norm(off)) - MARKER_OFFSET_M) < 1e-9
        # Out of the surface the head sees: toward the head, near W's origin.
        assert float(off @ -np.asarray(point["point_world_m"])) > 0
        if m["status"] == "ok":
            assert m["fixation"]["landed"][0] == TWIN_MARKER
            # Each eye's fixated point is its ray's nearest to the centre, not the sphere's
            # front (whose parallax alone is 0.14 deg at 0.5 m): the eyes meet there.
            assert max(m["fixation"]["error_m"]) < 1e-3
            assert m["fixation"]["vergence_error_deg"] < 0.05
    # The markerless run's truth is the point itself.
    for point, m in zip(points, markerless["measurements"], strict=True):
        np.testing.assert_allclose(m["truth_world_m"], point["point_world_m"], atol=1e-9)
