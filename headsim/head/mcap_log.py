"""A head's run as an MCAP file of ROS 2 messages, and that file read back.

:class:`RecordingHead` wraps any :class:`~headsim.head.interface.Head` and writes what
passes through it: each eye's ``sensor_msgs/Image`` (rgb8) and ``CameraInfo`` as the
head believes it, ``JointState``, the eye frames' TF from the joints and the head's
belief (a verged head's eye poses come from its joints, not a fixed stereo model),
the commands as ``ros2_control``'s forward controllers take them, and the estimates
(``geometry_msgs/PointStamped`` in the head frame).  :func:`read_log` reads such a
file, or a robot's (topics and joint names from a :class:`Topics` mapping).

Needs the ``mcap`` extra (``pip install 'headsim[mcap]'``).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np

from headsim.errors import BadInput, EnvironmentProblem
from headsim.geometry.kinematics import head_from_camera
from headsim.head.camera_info import CameraInfo
from headsim.head.interface import Head, JointReading, StampedImage, StereoFrame
from headsim.head.ros_messages import msgdef
from headsim.sim.render import Window
from headsim.sim.settings import HeadBelief


class LogError(BadInput, ValueError):
    """A recording that cannot be read as asked: the message says which topic or field."""


@dataclass(frozen=True)
class Topics:
    """Where a recording keeps each stream, and the robot's names of the head's joints
    (``joints``: headsim's name -> the robot's, e.g. ``{"eye": "l_eye_pan"}``) and their
    senses (``signs``: headsim's name -> 1 or -1, the robot's angle times it is headsim's,
    positive inward)."""

    images: tuple[str, str] = ("/cam1/image_raw", "/cam2/image_raw")
    camera_infos: tuple[str, str] = ("/cam1/camera_info", "/cam2/camera_info")
    joint_states: str = "/joint_states"
    tf: str = "/tf"
    position_commands: str = "/forward_position_controller/commands"
    velocity_commands: str = "/forward_velocity_controller/commands"
    estimates: str = "/headsim/estimates"
    phases: str = "/headsim/phase"
    joints: Mapping[str, str] = field(default_factory=dict)
    head_frame: str = "head"
    optical_frames: tuple[str, str] = ("cam1_optical", "cam2_optical")
    signs: Mapping[str, float] = field(default_factory=dict)

    def robot_joint(self, joint: str) -> str:
        """The robot's name of headsim's joint ``joint``."""
        return self.joints.get(joint, joint)

    def sign(self, joint: str) -> float:
        """1 or -1: headsim's angle of ``joint`` is the robot's times it (and the reverse)."""
        return self.signs.get(joint, 1.0)


def _stamp(time_s: float) -> dict[str, int]:
    ns = round(time_s * 1e9)
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _ns(time_s: float) -> int:
    return round(time_s * 1e9)


def _quaternion(rotation: np.ndarray) -> dict[str, float]:
    """(x, y, z, w) of a rotation matrix (Shepperd's method, w >= 0)."""
    m = rotation
    w = math.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1.0 + m[0, 0] - m[1, 1] - m[2, 2])) / 2, m[2, 1] - m[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1.0 - m[0, 0] + m[1, 1] - m[2, 2])) / 2, m[0, 2] - m[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1.0 - m[0, 0] - m[1, 1] + m[2, 2])) / 2, m[1, 0] - m[0, 1])
    return {"x": x, "y": y, "z": z, "w": w}


def believed_head_from_cameras(
    belief: HeadBelief,
    positions_rad: Mapping[str, float],
    alpha_e_rad: tuple[float, float] = (0.0, 0.0),
) -> tuple[np.ndarray, np.ndarray]:
    """Each eye's optical frame in H, 4 x 4, as the head believes it at these joint
    positions: each eye's angle plus its initial direction ``alpha_e_rad`` (0 until a
    calibration tells them), on the believed baseline and optical-centre offsets."""
    eyes = positions_rad
    angles = (eyes["eye"] + alpha_e_rad[0], eyes.get("eye2", eyes["eye"]) + alpha_e_rad[1])
    poses = [
        head_from_camera(
            camera,
            angles[camera - 1],
            belief.baseline_m,
            belief.nodal_offset_m[camera - 1],
            belief.side_offset_m[camera - 1],
        )
        for camera in (1, 2)
    ]
    return poses[0], poses[1]


class McapRecorder:
    """Writes ROS 2 messages to an MCAP file (zstd chunks); a context manager."""

    def __init__(self, path: str | Path, topics: Topics | None = None) -> None:
        try:
            from mcap_ros2.writer import Writer
        except ImportError:
            raise EnvironmentProblem(
                "recording to MCAP needs the mcap extra: pip install 'headsim[mcap]'"
            ) from None
        self.topics = topics or Topics()
        self.path = Path(path)
        self._file = self.path.open("wb")
        self._writer = Writer(self._file)
        self._schemas: dict[str, Any] = {}
        self._sequence = 0

    def _write(self, topic: str, datatype: str, message: dict[str, Any], time_s: float) -> None:
        schema = self._schemas.get(datatype)
        if schema is None:
            package, name = datatype.split("/")
            schema = self._schemas[datatype] = self._writer.register_msgdef(
                f"{package}/msg/{name}", msgdef(datatype)
            )
        self._sequence += 1
        self._writer.write_message(
            topic, schema, message, log_time=_ns(time_s), sequence=self._sequence
        )

    def image(
        self, camera: int, stamped: StampedImage, window: Window | None = None, binning: int = 1
    ) -> None:
        """Camera ``camera``'s image and its CameraInfo, both stamped with the image's time.

        ``window``: the image is only this region of interest of the full frame (the
        CameraInfo's ``roi``); ``binning``: the whole view binned b x b (its
        ``binning_x``/``binning_y``).  The CameraInfo's K, D, P stay the full frame's, as
        ROS has them."""
        image = np.ascontiguousarray(stamped.image, dtype=np.uint8)
        height, width = image.shape[:2]
        header = {
            "stamp": _stamp(stamped.time_s),
            "frame_id": self.topics.optical_frames[camera - 1],
        }
        info = stamped.camera_info
        self._write(
            self.topics.camera_infos[camera - 1],
            "sensor_msgs/CameraInfo",
            {
                "header": header,
                "height": info.height,
                "width": info.width,
                "distortion_model": info.distortion_model,
                "d": list(info.D),
                "k": list(info.K),
                "r": list(info.R),
                "p": list(info.P),
                "binning_x": binning if binning > 1 else 0,
                "binning_y": binning if binning > 1 else 0,
                "roi": {
                    "x_offset": 0 if window is None else window.x0,
                    "y_offset": 0 if window is None else window.y0,
                    "height": 0 if window is None else window.height,
                    "width": 0 if window is None else window.width,
                    "do_rectify": False,
                },
            },
            stamped.time_s,
        )
        self._write(
            self.topics.images[camera - 1],
            "sensor_msgs/Image",
            {
                "header": header,
                "height": height,
                "width": width,
                "encoding": "rgb8",
                "is_bigendian": 0,
                "step": width * 3,
                "data": image.tobytes(),
            },
            stamped.time_s,
        )

    def joints(self, reading: JointReading) -> None:
        """A ``JointState`` (the robot's joint names)."""
        names = list(reading.positions_rad)
        self._write(
            self.topics.joint_states,
            "sensor_msgs/JointState",
            {
                "header": {"stamp": _stamp(reading.time_s), "frame_id": ""},
                "name": [self.topics.robot_joint(n) for n in names],
                "position": [reading.positions_rad[n] * self.topics.sign(n) for n in names],
                "velocity": [
                    reading.velocities_rad_s.get(n, 0.0) * self.topics.sign(n) for n in names
                ],
                "effort": [],
            },
            reading.time_s,
        )

    def eye_frames(self, time_s: float, head_from_cameras: Sequence[np.ndarray]) -> None:
        """The eyes' optical frames in the head frame, one ``TFMessage``."""
        transforms = [
            {
                "header": {"stamp": _stamp(time_s), "frame_id": self.topics.head_frame},
                "child_frame_id": self.topics.optical_frames[index],
                "transform": {
                    "translation": dict(zip("xyz", (float(v) for v in pose[:3, 3]), strict=True)),
                    "rotation": _quaternion(pose[:3, :3]),
                },
            }
            for index, pose in enumerate(head_from_cameras)
        ]
        self._write(self.topics.tf, "tf2_msgs/TFMessage", {"transforms": transforms}, time_s)

    def command(self, kind: str, values: Mapping[str, float], time_s: float) -> None:
        """A forward controller's command (``kind``: "position" or "velocity"): one value
        per joint, labelled by the layout's dimension with the robot's joint names."""
        topic = (
            self.topics.position_commands if kind == "position" else self.topics.velocity_commands
        )
        names = list(values)
        self._write(
            topic,
            "std_msgs/Float64MultiArray",
            {
                "layout": {
                    "dim": [
                        {"label": self.topics.robot_joint(n), "size": 1, "stride": 1} for n in names
                    ],
                    "data_offset": 0,
                },
                "data": [float(values[n]) * self.topics.sign(n) for n in names],
            },
            time_s,
        )

    def estimate(self, name: str, point_head_m: np.ndarray, time_s: float) -> None:
        """An estimated point in the head frame (``frame_id``: ``head/NAME``)."""
        x, y, z = (float(v) for v in point_head_m)
        self._write(
            self.topics.estimates,
            "geometry_msgs/PointStamped",
            {
                "header": {"stamp": _stamp(time_s), "frame_id": f"{self.topics.head_frame}/{name}"},
                "point": {"x": x, "y": y, "z": z},
            },
            time_s,
        )

    def phase(self, name: str, time_s: float) -> None:
        """A procedure's phase ("calibration", "measurement") begins: a ``std_msgs/String``."""
        self._write(self.topics.phases, "std_msgs/String", {"data": name}, time_s)

    def close(self) -> None:
        self._writer.finish()
        self._file.close()

    def __enter__(self) -> McapRecorder:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, err: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()


class RecordingHead:
    """A :class:`Head` that records what passes through it to an :class:`McapRecorder`."""

    def __init__(self, head: Head, recorder: McapRecorder) -> None:
        self.head = head
        self.recorder = recorder

    @property
    def joint_names(self) -> tuple[str, ...]:
        return self.head.joint_names

    def joint_limits(self, joint: str) -> tuple[float, float]:
        return self.head.joint_limits(joint)

    def now(self) -> float:
        return self.head.now()

    @property
    def belief(self) -> HeadBelief:
        return self.head.belief

    def camera_infos(self) -> tuple[CameraInfo, CameraInfo]:
        return self.head.camera_infos()

    def read_joints(self) -> JointReading:
        reading = self.head.read_joints()
        self.recorder.joints(reading)
        self.recorder.eye_frames(
            reading.time_s, believed_head_from_cameras(self.belief, reading.positions_rad)
        )
        return reading

    def command_position(self, positions_rad: Mapping[str, float]) -> None:
        self.recorder.command("position", positions_rad, self.head.now())
        self.head.command_position(positions_rad)

    def command_velocity(self, velocities_rad_s: Mapping[str, float], duration_s: float) -> None:
        self.recorder.command("velocity", velocities_rad_s, self.head.now())
        self.head.command_velocity(velocities_rad_s, duration_s)

    def grab_stereo(self) -> StereoFrame:
        frame = self.head.grab_stereo()
        self.recorder.image(1, frame.left)
        self.recorder.image(2, frame.right)
        return frame


# -- reading ---------------------------------------------------------------------------


@dataclass(frozen=True)
class JointTrack:
    """Joint states over time: ``times_s`` (N,), ``positions_rad`` (N, J) by ``names``
    (headsim's names)."""

    names: tuple[str, ...]
    times_s: np.ndarray
    positions_rad: np.ndarray

    def at(self, time_s: float) -> dict[str, float]:
        """Each joint's position at ``time_s``, rad, linearly interpolated (held beyond the ends)."""
        return {
            name: float(np.interp(time_s, self.times_s, self.positions_rad[:, j]))
            for j, name in enumerate(self.names)
        }


@dataclass(frozen=True)
class Command:
    """A recorded forward-controller command: ``kind`` "position" or "velocity"."""

    time_s: float
    kind: str
    values: Mapping[str, float]


@dataclass(frozen=True)
class HeadLog:
    """A recording: each eye's stamped images, the joints, the commands and the estimates
    (name, time, point in H, m)."""

    images: tuple[tuple[StampedImage, ...], tuple[StampedImage, ...]]
    joints: JointTrack
    commands: tuple[Command, ...]
    estimates: tuple[tuple[str, float, np.ndarray], ...]


def _time(header: Any) -> float:
    return int(header.stamp.sec) + int(header.stamp.nanosec) * 1e-9


def _image(message: Any, topic: str) -> np.ndarray:
    if message.encoding not in ("rgb8", "bgr8"):
        raise LogError(f"{topic}: image encoding must be rgb8 or bgr8, got {message.encoding!r}")
    rows = np.frombuffer(bytes(message.data), dtype=np.uint8).reshape(message.height, message.step)
    image = rows[:, : message.width * 3].reshape(message.height, message.width, 3)
    return np.ascontiguousarray(image[..., ::-1] if message.encoding == "bgr8" else image)


def _messages(
    path: Path, topics: Sequence[str], in_time_order: bool = True
) -> Iterator[tuple[str, Any, float]]:
    """(topic, decoded message, log time in s) of ``topics``, in log-time order (else in
    the order written)."""
    try:
        from mcap.reader import make_reader
        from mcap_ros2.decoder import DecoderFactory
    except ImportError:
        raise EnvironmentProblem(
            "reading MCAP needs the mcap extra: pip install 'headsim[mcap]'"
        ) from None
    if not path.is_file():
        raise LogError(f"no recording {path}")
    with path.open("rb") as stream:
        try:
            reader = make_reader(stream, decoder_factories=[DecoderFactory()])
            for _, channel, message, decoded in reader.iter_decoded_messages(
                topics=list(topics), log_time_order=in_time_order
            ):
                yield channel.topic, decoded, message.log_time * 1e-9
        except LogError:
            raise
        except Exception as err:  # the readers raise their own types for a damaged file
            raise LogError(f"cannot read {path} as MCAP: {err}".splitlines()[0]) from None


def _info_at(infos: Sequence[tuple[float, CameraInfo]], time_s: float) -> CameraInfo:
    """The latest camera info logged at or before ``time_s`` (else the first)."""
    before = [info for t, info in infos if t <= time_s]
    return before[-1] if before else infos[0][1]


def read_log(path: str | Path, topics: Topics | None = None) -> HeadLog:
    """A recording's images (each with its camera's latest CameraInfo at or before it),
    joint states and commands (by headsim's joint names and senses: ``topics``' names
    and signs), and estimates."""
    topics = topics or Topics()
    robot_to_ours = {topics.robot_joint(n): n for n in ("neck_yaw", "neck_pitch", "eye", "eye2")}
    infos: tuple[list[tuple[float, CameraInfo]], ...] = ([], [])
    raw: tuple[list[tuple[float, np.ndarray]], ...] = ([], [])
    joint_rows: list[tuple[float, dict[str, float]]] = []
    commands: list[Command] = []
    estimates: list[tuple[str, float, np.ndarray]] = []
    wanted = (
        *topics.images,
        *topics.camera_infos,
        topics.joint_states,
        topics.position_commands,
        topics.velocity_commands,
        topics.estimates,
    )
    for topic, msg, log_time_s in _messages(Path(path), wanted):
        if topic in topics.camera_infos:
            infos[topics.camera_infos.index(topic)].append(
                (
                    _time(msg.header),
                    CameraInfo(
                        int(msg.width),
                        int(msg.height),
                        tuple(float(v) for v in msg.k),
                        tuple(float(v) for v in msg.d),
                        tuple(float(v) for v in msg.r),
                        tuple(float(v) for v in msg.p),
                        str(msg.distortion_model),
                        str(msg.header.frame_id),
                    ),
                )
            )
        elif topic in topics.images:
            raw[topics.images.index(topic)].append((_time(msg.header), _image(msg, topic)))
        elif topic == topics.joint_states:
            joint_rows.append(
                (
                    _time(msg.header),
                    {
                        robot_to_ours[n]: float(p) * topics.sign(robot_to_ours[n])
                        for n, p in zip(msg.name, msg.position, strict=False)
                        if n in robot_to_ours
                    },
                )
            )
        elif topic == topics.estimates:
            name = str(msg.header.frame_id).split("/", 1)[-1]
            point = np.array([msg.point.x, msg.point.y, msg.point.z], dtype=float)
            estimates.append((name, _time(msg.header), point))
        else:
            kind = "position" if topic == topics.position_commands else "velocity"
            labels = [d.label for d in msg.layout.dim]
            ours = [robot_to_ours.get(label, label) for label in labels]
            values = {n: float(v) * topics.sign(n) for n, v in zip(ours, msg.data, strict=False)}
            commands.append(Command(log_time_s, kind, values))
    images: list[tuple[StampedImage, ...]] = []
    for index in (0, 1):
        if not raw[index]:
            raise LogError(f"no images on {topics.images[index]}")
        if not infos[index]:
            raise LogError(f"no camera info on {topics.camera_infos[index]}")
        images.append(
            tuple(StampedImage(t, image, _info_at(infos[index], t)) for t, image in raw[index])
        )
    if not joint_rows:
        raise LogError(f"no joint states on {topics.joint_states}")
    names = tuple(n for n in ("neck_yaw", "neck_pitch", "eye", "eye2") if n in joint_rows[0][1])
    if "eye" not in names:
        raise LogError(
            f"{topics.joint_states} has no joint {topics.robot_joint('eye')!r} "
            "(map the robot's eye joint in [joints])"
        )
    joints = JointTrack(
        names,
        np.array([t for t, _ in joint_rows]),
        np.array([[row.get(n, math.nan) for n in names] for _, row in joint_rows]),
    )
    return HeadLog((images[0], images[1]), joints, tuple(commands), tuple(estimates))


@dataclass(frozen=True)
class Grab:
    """One image a head took, as recorded: camera 1 or 2, its stamp, the image, its region
    of interest in the full frame (None: the whole view) and binning (1: none), the
    joints' positions when it was taken (rad, headsim's names) and the phase under way."""

    camera: int
    time_s: float
    image: np.ndarray
    window: Window | None
    binning: int
    positions_rad: Mapping[str, float]
    phase: str


def read_grabs(path: str | Path, topics: Topics | None = None) -> tuple[Grab, ...]:
    """Every image of a recording in the order taken, windows and previews too, each with
    its CameraInfo's region of interest and binning and the joint state written before it
    (a servo's looks, as :class:`~headsim.runs.mcap_run.McapRun` records them)."""
    topics = topics or Topics()
    robot_to_ours = {topics.robot_joint(n): n for n in ("neck_yaw", "neck_pitch", "eye", "eye2")}
    grabs: list[Grab] = []
    info: list[Any] = [None, None]
    positions: dict[str, float] = {}
    phase = ""
    wanted = (*topics.images, *topics.camera_infos, topics.joint_states, topics.phases)
    for topic, msg, _ in _messages(Path(path), wanted, in_time_order=False):
        if topic == topics.phases:
            phase = str(msg.data)
        elif topic == topics.joint_states:
            positions = {
                robot_to_ours[n]: float(p)
                for n, p in zip(msg.name, msg.position, strict=False)
                if n in robot_to_ours
            }
        elif topic in topics.camera_infos:
            info[topics.camera_infos.index(topic)] = msg
        else:
            camera = topics.images.index(topic) + 1
            roi = None if info[camera - 1] is None else info[camera - 1].roi
            window = (
                Window(int(roi.x_offset), int(roi.y_offset), int(roi.width), int(roi.height))
                if roi is not None and roi.width and roi.height
                else None
            )
            binning = 1 if info[camera - 1] is None else max(1, int(info[camera - 1].binning_x))
            image = _image(msg, topic)
            grabs.append(
                Grab(camera, _time(msg.header), image, window, binning, dict(positions), phase)
            )
    return tuple(grabs)


__all__ = [
    "Command",
    "Grab",
    "HeadLog",
    "JointTrack",
    "LogError",
    "McapRecorder",
    "RecordingHead",
    "Topics",
    "believed_head_from_cameras",
    "read_grabs",
    "read_log",
]
