"""The headsim command line, run as a user runs it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np

from headsim.cli import main
from headsim.vision.markers import find_marker


def test_snapshot_writes_images_and_ground_truth(tmp_path: Path) -> None:
    out = tmp_path / "snap"
    assert main(["snapshot", "--out", str(out), "--preset", "paper", "--eye", "0.04"]) == 0
    truth = json.loads((out / "truth.json").read_text())
    assert truth["settings"]["cameras"][0]["kx"] == 834.83
    assert truth["truth"]["eye_encoder_steps"] == round(
        0.04 / truth["settings"]["encoder_resolution_rad"]
    )
    for index, cam in enumerate(("cam1", "cam2")):
        image = cv2.cvtColor(cv2.imread(str(out / f"{cam}.png")), cv2.COLOR_BGR2RGB)
        assert image.shape == (480, 640, 3)
        # The PNG shows the marker where the JSON says it projects.
        detection = find_marker(image, "red")
        expected = np.array(truth["truth"]["targets"]["marker_red"][f"{cam}_px"])
        assert np.linalg.norm(np.array(detection.uv) - expected) < 0.15, (index, detection)
    overview = cv2.imread(str(out / "overview.png"))
    assert overview.shape[1] > 1280
    assert not list(out.glob(".*.tmp"))  # atomic writes leave no temporaries


def test_snapshot_of_another_scene(tmp_path: Path) -> None:
    assert main(["snapshot", "--out", str(tmp_path), "--scene", "chessboard"]) == 0
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert "chessboard" in truth["truth"]["targets"]


def test_bad_arguments_name_the_problem(tmp_path: Path) -> None:
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "headsim.cli",
            "snapshot",
            "--out",
            str(tmp_path),
            "--scene",
            "kitchen",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    assert "unknown scene 'kitchen'; allowed: base, blocks, chessboard, default" in result.stderr
    assert not (tmp_path / "truth.json").exists()
    result = subprocess.run(
        [sys.executable, "-m", "headsim.cli", "snapshot", "--out", str(tmp_path), "--eye", "2.0"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    assert "outside its range" in result.stderr


def test_help_is_available() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "headsim.cli", "snapshot", "--help"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0
    assert "--preset" in result.stdout
