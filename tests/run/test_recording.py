"""The Rerun recording (run/recording.py), read back with ``rerun.chunk.RrdReader``: the
documented entities at their steps, the head and its scene, the results, and the rows
sent as columns."""

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
import rerun as rr
from rerun.chunk import RrdReader

from headsim.runs.recording import RowColumns

from .rrd import rows

ROOT = Path(__file__).resolve().parents[2]
RECORDING_PAGE = ROOT / "docs" / "how-to" / "record.md"


def test_the_file_is_complete_with_its_blueprint(recorded: tuple[Path, dict]) -> None:
    rrd, _ = recorded
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a file without footer would warn
        reader = RrdReader(rrd)
        assert [r.recording_id for r in reader.recordings()] == ["quickstart-fast-seed0"]
        assert len(reader.blueprints()) == 1


def _rows_per_entity(rrd: Path) -> dict[str, int]:
    counts: dict[str, int] = defaultdict(int)
    for chunk in RrdReader(rrd).stream():
        counts[chunk.entity_path] += chunk.to_record_batch().num_rows
    return dict(counts)


def test_the_command_line_leaves_only_once_the_recording_is_complete(
    recorded: tuple[Path, dict], tmp_path: Path
) -> None:
    # The process's own entry point: the recording it wrote has its footer and every
    # row of a run in-process.
    out, rrd = tmp_path / "out", tmp_path / "run.rrd"
    command = [sys.executable, "-m", "headsim.cli", "run", "quickstart", "--fast"]
    command += ["--out", str(out), "--rrd", str(rrd), "--no-progress"]
    done = subprocess.run(
        command, capture_output=True, text=True, timeout=300, check=False,
        env={**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "recording" in done.stdout  # stdout was flushed before leaving
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a file without footer would warn
        assert len(RrdReader(rrd).blueprints()) == 1
    assert _rows_per_entity(rrd) == _rows_per_entity(recorded[0])
    assert (out / "results.json").read_text() == (recorded[0].parent / "results.json").read_text()


def test_every_recorded_entity_is_documented(recorded: tuple[Path, dict]) -> None:
    rrd, _ = recorded
    text = RECORDING_PAGE.read_text()
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
    # The model's bodies and geoms: one row of the page stands for them (tests/run/test_mjcf_rerun.py).
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
    images = rows(rrd, "/world/head/cam1/image", "EncodedImage:blob")
    assert len(images) > 5
    counts: dict[str, int] = defaultdict(int)
    for chunk in RrdReader(rrd).stream():
        counts[chunk.entity_path] += 1
    assert counts["/world/head"] > 0


# -- the head and its scene


def test_frusta_images_and_features_at_every_frame(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    counts = results["render_counts"]["overall"]
    total = counts["total"] - counts["previews"]  # the recording shows no preview
    frames = []
    for cam in ("cam1", "cam2"):
        pinhole = rows(rrd, f"/world/head/{cam}", "Pinhole:image_from_camera")
        assert len(pinhole) == 1 and pinhole[0]["frame"] is None  # static: the true K
        k = np.array(pinhole[0]["value"]).reshape(3, 3).T  # column-major
        expected = results["settings"]["cameras"][0 if cam == "cam1" else 1]
        np.testing.assert_allclose(k[0], [expected["kx"], 0, expected["cx"]], rtol=1e-6)
        images = rows(rrd, f"/world/head/{cam}/image", "EncodedImage:blob")
        frames += [r["frame"] for r in images]
        rows_of_features = rows(rrd, f"/world/head/{cam}/features", "Points2D:positions")
        # Each image first empties the features (the last detection does not linger) ...
        emptied = {r["frame"] for r in rows_of_features if not r["value"]}
        assert {r["frame"] for r in images} <= emptied
        # ... then its detection, if any, follows at the same frame.
        features = [r for r in rows_of_features if r["value"]]
        assert {r["frame"] for r in features} <= {r["frame"] for r in images}
        assert all(len(r["value"]) == 1 for r in features)
        assert len(features) > 0.8 * len(images)  # nearly every image had its target found
        u_error = rows(rrd, f"/servo/{cam}/u_error_px", "Scalars:scalars")
        assert [r["frame"] for r in u_error] == [r["frame"] for r in features]
    # Every image the run took is in the recording once, in order, and no other.
    assert sorted(frames) == list(range(total))
    transforms = rows(rrd, "/world/head/cam1", "Transform3D:translation")
    assert set(frames) <= {r["frame"] for r in transforms}
    for joint in ("eye_rad", "neck_yaw_rad", "neck_pitch_rad"):
        assert set(frames) <= {r["frame"] for r in rows(rrd, f"/joints/{joint}", "Scalars:scalars")}


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
        rotations = rows(rrd, f"/world/model/{eye}", "Transform3D:quaternion")
        assert len({tuple(r["value"][0]) for r in rotations}) > 5  # the eyes turned
    eye_rad = rows(rrd, "/joints/eye_rad", "Scalars:scalars")[-1]["value"][0]
    eye1 = np.array(rows(rrd, "/world/model/eye1", "Transform3D:quaternion")[-1]["value"][0])
    head = np.array(rows(rrd, "/world/model/head", "Transform3D:quaternion")[-1]["value"][0])
    # eye1 is turned from the head's frame by the eye angle (to an encoder step).
    angle = 2 * np.arccos(min(1.0, abs(float(np.dot(eye1, head)))))
    assert angle == pytest.approx(abs(eye_rad), abs=1e-3)


# -- the results


def test_true_and_estimated_points_at_each_measurement_step(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    measurements = results["measurements"]
    estimates = rows(rrd, "/world/estimate", "Points3D:positions")
    assert [r["step"] for r in estimates] == [m["step"] for m in measurements]
    # The last row holds every estimate, where results.json has them.
    np.testing.assert_allclose(
        np.array(estimates[-1]["value"]), [m["estimate_world_m"] for m in measurements], atol=1e-6
    )
    truth = rows(rrd, "/world/truth", "Points3D:positions")
    np.testing.assert_allclose(
        np.array(truth[-1]["value"]), [m["truth_world_m"] for m in measurements], atol=1e-6
    )
    errors = rows(rrd, "/measurements/error_mm", "Scalars:scalars")
    assert [r["step"] for r in errors] == [m["step"] for m in measurements]
    np.testing.assert_allclose(
        [r["value"][0] for r in errors], [1000 * m["error_m"] for m in measurements], rtol=1e-6
    )
    calibration = rows(rrd, "/world/calibration/positions", "Points3D:positions")
    assert len(calibration[0]["value"]) == results["calibration"]["targets"]
    steps = {r["step"] for r in rows(rrd, "/world/current_target", "Points3D:positions")}
    assert steps == set(range(results["calibration"]["targets"] + len(measurements)))


def test_results_are_in_the_recording_as_text(recorded: tuple[Path, dict]) -> None:
    rrd, results = recorded
    summary = rows(rrd, "/results/summary", "TextDocument:text")
    assert "OK: 3 measurements, none failed" in summary[-1]["value"][0]
    calibration = rows(rrd, "/results/calibration", "TextDocument:text")
    text = calibration[-1]["value"][0]
    assert f"{results['calibration']['alpha_e_rad'][0]:.5f}" in text and "0.0578" in text


# -- rows sent as columns


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


def test_a_target_measured_again_knowing_more_is_labelled_with_what_it_knew(
    tmp_path: Path,
) -> None:
    """The calibration procedure measures each check target before and after calibrating:
    the second estimate's label says so (found from the records, not the procedure's name)."""
    from headsim.cli import main

    rrd = tmp_path / "calibration.rrd"
    argv = ["run", "calibration", "--fast", "--out", str(tmp_path), "--rrd", str(rrd)]
    assert main([*argv, "--no-progress"]) == 0
    measurements = json.loads((tmp_path / "results.json").read_text())["measurements"]
    labels = rows(rrd, "/world/estimate", "Points3D:labels")[-1]["value"]
    ok = [m for m in measurements if m["status"] == "ok"]
    assert len(labels) == len(ok) >= 2
    first = {m["name"] for m in ok if m["knowledge"] == "none"}
    assert {m["name"] for m in ok if m["knowledge"] == "calibrated"} & first
    for m, label in zip(ok, labels, strict=True):
        again = m["knowledge"] == "calibrated" and m["name"] in first
        assert label == (f"{m['name']} (calibrated)" if again else m["name"])
