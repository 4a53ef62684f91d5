"""The head and its scene in the recording: frusta, images, features, geometry, moving eyes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from .rrd import rows


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
