"""One look through both eyes, written to real files and read back (real MuJoCo renders)."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np

from headsim.sim import names
from headsim.sim.settings import ideal_head
from headsim.sim.simulator import HeadSim
from headsim.sim.snapshot import ground_truth, movable_bodies, overview, take_snapshot


def test_the_snapshot_writes_what_the_simulator_saw(tmp_path: Path) -> None:
    written = take_snapshot(tmp_path / "snap", "default", ideal_head(), neck_yaw=0.05, eye=0.03)
    assert sorted(written) == ["cam1", "cam2", "overview", "truth"]
    payload = json.loads(written["truth"].read_text())
    assert payload["command_rad"] == {"neck_yaw": 0.05, "neck_pitch": 0.0, "eye": 0.03}
    assert payload["renders"] == 2
    truth = payload["truth"]
    assert (
        truth["eye_encoder_rad"] == truth["eye_encoder_steps"] * ideal_head().encoder_resolution_rad
    )
    assert abs(truth["eye_encoder_rad"] - 0.03) <= ideal_head().encoder_resolution_rad
    for cam in names.CAMERAS:
        image = cv2.imread(str(written[cam]))
        assert image.shape == (480, 640, 3)
        assert np.asarray(truth["cameras"][cam]["K"]).shape == (3, 3)
    assert cv2.imread(str(written["overview"])).shape == (480, 2 * (640 + 4), 3)
    assert not list((tmp_path / "snap").glob(".*.tmp"))  # atomic writes


def test_targets_behind_a_camera_have_no_pixel_and_the_overview_marks_the_centre() -> None:
    with HeadSim("default", ideal_head()) as sim:
        bodies = movable_bodies(sim)
        assert set(names.MARKERS) <= set(bodies)
        sim.set_body_pose(names.MARKERS[0], [0.0, -1.0, 0.2])  # behind the head
        truth = ground_truth(sim)
        images = [sim.render(cam) for cam in names.CAMERAS]
    behind = truth["targets"][names.MARKERS[0]]
    assert behind["cam1_px"] is None and behind["cam2_px"] is None
    assert behind["cam1_m"][2] < 0
    drawn = overview(images, truth)
    for index, cam in enumerate(names.CAMERAS):
        u0, v0 = truth["cameras"][cam]["image_centre"]
        x = index * (640 + 4) + round(u0)
        assert tuple(drawn[round(v0), x]) == (255, 255, 255)  # the centre's cross
