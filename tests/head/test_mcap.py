"""A head's run recorded as ROS 2 messages in MCAP: read back by the mcap reader, opened by
Rerun's MCAP importer, and replayed bit for bit."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from headsim.head.camera_info import camera_info_of
from headsim.head.interface import Head, JointReading, StampedImage, StereoFrame
from headsim.head.mcap_log import (
    Command,
    HeadLog,
    JointTrack,
    McapRecorder,
    RecordingHead,
    Topics,
    read_log,
)
from headsim.head.replay import ReplayDiverged, ReplayHead, pair_by_stamp
from headsim.head.sim_head import FRAME_PERIOD_S, SimHead
from headsim.head.stereo_look import StereoEstimate, look_and_estimate, triangulate_rays
from headsim.sim.names import MARKER_COLOURS
from headsim.sim.settings import SettingsError, ideal_head
from headsim.sim.simulator import HeadSim

#: The eye poses the recorded procedure turns to, rad.
POSES = ({"eye": 0.0}, {"eye": 0.05}, {"eye": 0.1})

TOPICS = {
    "/cam1/image_raw": "sensor_msgs/msg/Image",
    "/cam2/image_raw": "sensor_msgs/msg/Image",
    "/cam1/camera_info": "sensor_msgs/msg/CameraInfo",
    "/cam2/camera_info": "sensor_msgs/msg/CameraInfo",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/forward_position_controller/commands": "std_msgs/msg/Float64MultiArray",
}


@dataclass(frozen=True)
class Recorded:
    path: Path
    estimates: list[StereoEstimate]
    truth_head_m: dict[str, np.ndarray]
    first_frame: StereoFrame


class _Keep(RecordingHead):
    """Records, and keeps the first frame for comparing."""

    first: StereoFrame | None = None

    def grab_stereo(self) -> StereoFrame:
        frame = super().grab_stereo()
        self.first = self.first or frame
        return frame


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Recorded:
    path = tmp_path_factory.mktemp("mcap") / "run.mcap"
    with HeadSim("default", ideal_head()) as sim, McapRecorder(path) as recorder:
        head = _Keep(SimHead(sim), recorder)
        estimates = look_and_estimate(head, POSES, MARKER_COLOURS)
        for e in estimates:
            recorder.estimate(e.name, e.point_head_m, e.time_s)
        truth = {name: sim.truth.position(name, "head") for name in MARKER_COLOURS}
    assert head.first is not None
    return Recorded(path, estimates, truth, head.first)


@pytest.mark.render
def test_the_recording_reads_back_with_the_mcap_reader(recorded: Recorded) -> None:
    with recorded.path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None
    channels = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
    assert channels == {**TOPICS, "/headsim/estimates": "geometry_msgs/msg/PointStamped"}
    counts = {
        summary.channels[cid].topic: n
        for cid, n in summary.statistics.channel_message_counts.items()
    }
    pairs = len(POSES)
    assert counts["/cam1/image_raw"] == counts["/cam2/camera_info"] == pairs
    assert counts["/joint_states"] == counts["/tf"] == pairs
    assert counts["/headsim/estimates"] == pairs * len(MARKER_COLOURS)
    log = read_log(recorded.path)
    first = log.images[0][0]
    assert np.array_equal(first.image, recorded.first_frame.left.image)
    assert first.camera_info == replace(
        recorded.first_frame.left.camera_info, frame_id="cam1_optical"
    )
    assert [c.values for c in log.commands] == list(POSES)
    assert [name for name, _, _ in log.estimates] == [e.name for e in recorded.estimates]


@pytest.mark.render
def test_the_estimates_are_near_the_truth(recorded: Recorded) -> None:
    for e in recorded.estimates:
        assert e.status == "ok"
        error = np.linalg.norm(e.point_head_m - recorded.truth_head_m[e.name])
        assert error < 0.002 * e.point_head_m[2], (e.name, error)


@pytest.mark.render
def test_a_replay_gives_the_same_estimates_bit_for_bit(recorded: Recorded) -> None:
    replayed = look_and_estimate(ReplayHead(read_log(recorded.path)), POSES, MARKER_COLOURS)
    assert len(replayed) == len(recorded.estimates)
    for a, b in zip(recorded.estimates, replayed, strict=True):
        assert a.name == b.name and a.uv_px == b.uv_px
        assert abs(a.time_s - b.time_s) < 1e-9  # ROS stamps are whole nanoseconds
        assert a.point_head_m.tobytes() == b.point_head_m.tobytes()


@pytest.mark.render
def test_a_replay_refuses_a_command_the_recording_did_not_make(recorded: Recorded) -> None:
    head = ReplayHead(read_log(recorded.path))
    with pytest.raises(ReplayDiverged, match="command 1 differs"):
        head.command_position({"eye": 0.2})


@pytest.mark.render
def test_rerun_imports_the_images_cameras_joints_and_tf(recorded: Recorded, tmp_path: Path) -> None:
    rerun = Path(sys.executable).with_name("rerun")
    rrd = tmp_path / "run.rrd"
    subprocess.run(
        [str(rerun), "mcap", "convert", str(recorded.path), "-o", str(rrd)],
        check=True,
        capture_output=True,
        timeout=120,
    )
    printed = subprocess.run(
        [str(rerun), "rrd", "print", str(rrd)],
        check=True,
        capture_output=True,
        text=True,
        timeout=120,
    ).stdout
    chunks = [line for line in printed.splitlines() if line.startswith("Chunk(")]

    def columns(entity: str) -> str:
        return " ".join(line for line in chunks if f"- {entity} - " in line)

    for camera in ("cam1", "cam2"):
        assert columns(f"/{camera}/image_raw").count("Image:buffer") == len(POSES)
        assert "Pinhole:image_from_camera" in columns(f"/{camera}/camera_info")
    assert columns("/joint_states/position").count("Scalars:scalars") == len(POSES)
    assert "Transform3D:quaternion" in columns("/tf")


def _image(time_s: float, value: int) -> StampedImage:
    info = camera_info_of(ideal_head().cameras[0].pinhole())
    return StampedImage(time_s, np.full((2, 2, 3), value, np.uint8), info)


@pytest.mark.fast
def test_pairs_by_nearest_stamp_and_joints_at_the_image_time() -> None:
    left = (_image(0.0, 1), _image(0.1, 2), _image(0.2, 3))
    right = (_image(0.004, 11), _image(0.093, 12), _image(0.13, 13), _image(0.21, 14))
    pairs = pair_by_stamp(left, right)
    assert [int(p.right.image[0, 0, 0]) for p in pairs] == [11, 12, 14]
    assert pairs[1].skew_s == pytest.approx(-0.007)
    track = JointTrack(("eye",), np.array([0.0, 0.08, 0.2]), np.array([[0.0], [0.08], [0.1]]))
    log = HeadLog((left, right), track, (Command(0.0, "position", {"eye": 0.0}),), ())
    head = ReplayHead(log)
    head.command_position({"eye": 0.0})
    readings: list[JointReading] = []
    for _ in range(3):
        readings.append(head.read_joints())
        head.grab_stereo()
    # the pair's time is the mean of its stamps; the joints interpolated there
    times = [p.time_s for p in pairs]
    assert [r.time_s for r in readings] == times
    expected = np.interp(times, [0.0, 0.08, 0.2], [0.0, 0.08, 0.1])
    assert [r.positions_rad["eye"] for r in readings] == pytest.approx(expected, abs=1e-15)
    with pytest.raises(ReplayDiverged, match="holds 3 stereo pairs"):
        head.grab_stereo()


@pytest.mark.fast
def test_rays_meet_at_the_point_they_were_cast_through() -> None:
    point = np.array([0.03, -0.02, 0.7])
    origins = [np.array([-0.075, 0.0, 0.0]), np.array([0.075, 0.001, 0.0])]
    found, gap = triangulate_rays(origins, [point - o for o in origins])
    assert np.allclose(found, point, atol=1e-12) and gap < 1e-12
    skew = [point - origins[0], point + np.array([0.0, 0.002, 0.0]) - origins[1]]
    _, gap = triangulate_rays(origins, skew)
    assert gap == pytest.approx(0.002, rel=0.05)
    with pytest.raises(ValueError, match="parallel"):
        triangulate_rays(origins, [np.array([0, 0, 1.0]), np.array([0, 0, 2.0])])


@pytest.mark.render
def test_the_simulator_is_a_head() -> None:
    with HeadSim("default", ideal_head()) as sim:
        head = SimHead(sim)
        assert isinstance(head, Head)
        assert head.joint_names == ("neck_yaw", "neck_pitch", "eye")
        head.command_velocity({"eye": 0.1}, 0.5)
        reading = head.read_joints()
        steps = round(0.05 / sim.settings.encoder_resolution_rad)
        assert reading.positions_rad["eye"] == steps * sim.settings.encoder_resolution_rad
        assert reading.time_s == 0.5
        frame = head.grab_stereo()
        assert frame.skew_s == 0.0 and frame.left.time_s == 0.5
        assert frame.left.image.shape == (480, 640, 3)
        assert head.now() == pytest.approx(0.5 + FRAME_PERIOD_S)
        with pytest.raises(SettingsError, match="no motor 'eye2'"):
            head.command_velocity({"eye2": 0.1}, 0.1)


def test_a_robot_whose_eye_turns_the_other_way_is_read_in_headsims_sense(tmp_path: Path) -> None:
    """``Topics.signs``: the recorder writes the robot's names and senses, and the reader
    gives headsim's back; read without the signs, the eye's angles come back negated."""
    robot = Topics(joints={"eye": "l_eye_pan"}, signs={"eye": -1.0})
    path = tmp_path / "robot.mcap"
    sent = [JointReading(0.1 * k, {"neck_yaw": 0.01 * k, "eye": 0.02 * k}, {}) for k in range(4)]
    with HeadSim("default", ideal_head()) as sim, McapRecorder(path, robot) as recorder:
        frame = SimHead(sim).grab_stereo()
        recorder.image(1, frame.left)
        recorder.image(2, frame.right)
        for reading in sent:
            recorder.joints(reading)
        recorder.command("position", {"eye": 0.03}, 0.5)
    ours = read_log(path, robot)
    assert [ours.joints.at(r.time_s)["eye"] for r in sent] == [r.positions_rad["eye"] for r in sent]
    assert ours.commands[-1].values == {"eye": 0.03}
    as_sent = read_log(path, Topics(joints={"eye": "l_eye_pan"}))
    assert [as_sent.joints.at(r.time_s)["eye"] for r in sent] == [
        -r.positions_rad["eye"] for r in sent
    ]
    assert as_sent.commands[-1].values == {"eye": -0.03}
