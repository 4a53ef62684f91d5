"""The Rerun recording, read back with ``rerun.chunk.RrdReader``: the documented entities at their steps."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from headsim.cli import main

README = Path(__file__).resolve().parents[2] / "README.md"
ROOT = README.parent


def _rows(path: Path, entity: str, component: str) -> list[dict[str, object]]:
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


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("quickstart")
    rrd = out / "recording.rrd"
    assert (
        main(["run", "quickstart", "--fast", "--out", str(out), "--rrd", str(rrd), "--no-progress"])
        == 0
    )
    return rrd, json.loads((out / "results.json").read_text())


def test_the_file_is_complete_with_its_blueprint(recorded: tuple[Path, dict]) -> None:
    rrd, _ = recorded
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a file without footer would warn
        reader = RrdReader(rrd)
        assert [r.recording_id for r in reader.recordings()] == ["quickstart-fast-seed0"]
        assert len(reader.blueprints()) == 1


def test_frusta_images_and_features_at_every_frame(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    total = results["renders"]["total"]
    frames = []
    for cam in ("cam1", "cam2"):
        pinhole = _rows(rrd, f"/world/head/{cam}", "Pinhole:image_from_camera")
        assert len(pinhole) == 1 and pinhole[0]["frame"] is None  # static: the true K
        k = np.array(pinhole[0]["value"]).reshape(3, 3).T  # column-major
        expected = results["settings"]["cameras"][0 if cam == "cam1" else 1]
        np.testing.assert_allclose(k[0], [expected["kx"], 0, expected["cx"]], rtol=1e-6)
        images = _rows(rrd, f"/world/head/{cam}/image", "EncodedImage:blob")
        frames += [r["frame"] for r in images]
        features = _rows(rrd, f"/world/head/{cam}/features", "Points2D:positions")
        assert {r["frame"] for r in features} <= {r["frame"] for r in images}
        assert len(features) > 0.8 * len(images)  # nearly every image had its target found
        u_error = _rows(rrd, f"/servo/{cam}/u_error_px", "Scalars:scalars")
        assert [r["frame"] for r in u_error] == [r["frame"] for r in features]
    # Every image the run took is in the recording once, in order, and no other.
    assert sorted(frames) == list(range(total))
    transforms = _rows(rrd, "/world/head/cam1", "Transform3D:translation")
    assert set(frames) <= {r["frame"] for r in transforms}
    for joint in ("eye_rad", "neck_yaw_rad", "neck_pitch_rad"):
        assert set(frames) <= {
            r["frame"] for r in _rows(rrd, f"/joints/{joint}", "Scalars:scalars")
        }


def test_true_and_estimated_points_at_each_measurement_step(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    measurements = results["measurements"]
    estimates = _rows(rrd, "/world/estimate", "Points3D:positions")
    assert [r["step"] for r in estimates] == [m["step"] for m in measurements]
    # The last row holds every estimate, where results.json has them.
    np.testing.assert_allclose(
        np.array(estimates[-1]["value"]), [m["estimate_world_m"] for m in measurements], atol=1e-6
    )
    truth = _rows(rrd, "/world/truth", "Points3D:positions")
    np.testing.assert_allclose(
        np.array(truth[-1]["value"]), [m["truth_world_m"] for m in measurements], atol=1e-6
    )
    errors = _rows(rrd, "/measurements/error_mm", "Scalars:scalars")
    assert [r["step"] for r in errors] == [m["step"] for m in measurements]
    np.testing.assert_allclose(
        [r["value"][0] for r in errors], [1000 * m["error_m"] for m in measurements], rtol=1e-6
    )
    calibration = _rows(rrd, "/world/calibration/positions", "Points3D:positions")
    assert len(calibration[0]["value"]) == results["calibration"]["targets"]
    steps = {r["step"] for r in _rows(rrd, "/world/current_target", "Points3D:positions")}
    assert steps == set(range(results["calibration"]["targets"] + len(measurements)))


def test_results_are_in_the_recording_as_text(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    summary = _rows(rrd, "/results/summary", "TextDocument:text")
    assert "OK: 3 measurements, none failed" in summary[-1]["value"][0]
    calibration = _rows(rrd, "/results/calibration", "TextDocument:text")
    text = calibration[-1]["value"][0]
    assert f"{results['calibration']['alpha_e_rad'][0]:.5f}" in text and "0.0578" in text


def test_every_recorded_entity_is_documented(recorded: tuple[Path, dict]) -> None:
    rrd, _ = recorded
    text = README.read_text()
    table = text[text.index("| entity | type | what |") :].split("\n\n")[0]
    documented = set()
    for cell in re.findall(r"^\| ([^|]+) \|", table, re.M):
        paths = re.findall(r"`([^`]+)`", cell)
        if not paths:
            continue
        base = paths[0]
        for p in paths:
            documented.add(base.rsplit("/", 2)[0] + p[3:] if p.startswith("...") else p)
    recorded_entities = {
        chunk.entity_path
        for chunk in RrdReader(rrd).stream()
        if not chunk.entity_path.startswith("/__")
    }
    # The model's bodies and geoms: one README row stands for them (tests/run/test_mjcf_rerun.py).
    assert "`/world/model/BODY`" in table
    recorded_entities = {e for e in recorded_entities if not e.startswith("/world/model/")}
    assert recorded_entities <= documented, recorded_entities - documented


def test_an_interrupted_run_leaves_a_readable_recording_and_no_results(tmp_path: Path) -> None:
    out, rrd = tmp_path / "out", tmp_path / "run.rrd"
    command = [
        sys.executable,
        "-m",
        "headsim.cli",
        "run",
        "chessboard",
        "--out",
        str(out),
        "--rrd",
        str(rrd),
    ]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        command, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        deadline = time.monotonic() + 60
        # Wait for the first flushed measurements (a few hundred kB of images).
        while time.monotonic() < deadline and (not rrd.exists() or rrd.stat().st_size < 300_000):
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.1)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "interrupted: nothing written to" in err
    assert not (out / "results.json").exists()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # closed with its footer
        reader = RrdReader(rrd)
        assert len(reader.recordings()) == 1
    images = _rows(rrd, "/world/head/cam1/image", "EncodedImage:blob")
    assert len(images) > 5
    counts: dict[str, int] = defaultdict(int)
    for chunk in RrdReader(rrd).stream():
        counts[chunk.entity_path] += 1
    assert counts["/world/head"] > 0


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


def test_the_head_and_scene_are_in_3d_and_the_eyes_move(recorded: tuple[Path, dict]) -> None:
    rrd, _ = recorded
    static = {
        chunk.entity_path
        for chunk in RrdReader(rrd).stream()
        if chunk.entity_path.startswith("/world/model/") and chunk.is_static
    }
    # The default scene (calibration and measurements): head, table, markers, ball.
    for entity in (
        "/world/model/head/boxes",
        "/world/model/eye1/cylinders",
        "/world/model/eye2/cylinders",
        "/world/model/neck_yaw_link/cylinders",
        "/world/model/world/boxes",
        "/world/model/marker_red/ellipsoids",
        "/world/model/calibration_ball/ellipsoids",
    ):
        assert entity in static, entity
    for eye in ("eye1", "eye2"):
        rotations = _rows(rrd, f"/world/model/{eye}", "Transform3D:quaternion")
        assert len({tuple(r["value"][0]) for r in rotations}) > 5  # the eyes turned
    eye_rad = _rows(rrd, "/joints/eye_rad", "Scalars:scalars")[-1]["value"][0]
    eye1 = np.array(_rows(rrd, "/world/model/eye1", "Transform3D:quaternion")[-1]["value"][0])
    head = np.array(_rows(rrd, "/world/model/head", "Transform3D:quaternion")[-1]["value"][0])
    # eye1 is turned from the head's frame by the eye angle (to an encoder step).
    angle = 2 * np.arccos(min(1.0, abs(float(np.dot(eye1, head)))))
    assert angle == pytest.approx(abs(eye_rad), abs=1e-3)
