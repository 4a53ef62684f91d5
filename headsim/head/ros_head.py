"""A live head over ROS 2 (the ``ros`` extra): :class:`RosHead` is the
:class:`~headsim.head.interface.Head` interface, and the
:class:`~headsim.head.servo_head.ServoHead` the servos and procedures drive
(:class:`~headsim.head.ros_servo.RosServo`), on a robot's topics and its
``ros2_control`` forward controllers.

It subscribes to each eye's ``sensor_msgs/Image`` (rgb8 or bgr8) and ``CameraInfo``
and to ``JointState``; it commands through ``std_msgs/Float64MultiArray`` on the
forward position and velocity controllers' ``~/commands`` (values in
``joint_names`` order, each dimension labelled with the joint's name).  A position
command ends with the first joint state stamped after it that has every named joint
within ``tolerance_rad`` of it; a grab waits for images stamped at or after that state
(a stereo pair: Ca1's with Ca2's nearest in time; one eye's: its next).  Topic and
joint names: a :class:`~headsim.head.mcap_log.Topics` (the mapping file's).
Installing: see docs/how-to/real-head.md.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from headsim.errors import EnvironmentProblem, JobFailed
from headsim.head.camera_info import CameraInfo
from headsim.head.interface import JointReading, StampedImage, StereoFrame
from headsim.head.mcap_log import Topics
from headsim.head.ros_servo import RosServo, binned
from headsim.sim.events import NO_EVENTS, EventSink, ImageKind
from headsim.sim.heads import PAPER, HeadModel
from headsim.sim.settings import HeadBelief


def ros_modules() -> tuple[Any, Any, Any, Any]:
    """(rclpy, sensor_msgs.msg, std_msgs.msg, rclpy.qos), or EnvironmentProblem saying
    what to install."""
    try:
        import rclpy
        import rclpy.qos
        import sensor_msgs.msg
        import std_msgs.msg
    except ImportError as err:
        raise EnvironmentProblem(
            "the ROS 2 head needs rclpy and its messages: pip install 'headsim[ros]' "
            f"(or source a ROS 2 install): {err}"
        ) from None
    return rclpy, sensor_msgs.msg, std_msgs.msg, rclpy.qos


def latched_qos() -> Any:
    """Reliable, transient-local, depth 1: a late subscriber gets the last message."""
    qos = ros_modules()[3]
    return qos.QoSProfile(
        depth=1,
        reliability=qos.ReliabilityPolicy.RELIABLE,
        durability=qos.DurabilityPolicy.TRANSIENT_LOCAL,
    )


def stamp_s(header: Any) -> float:
    return int(header.stamp.sec) + int(header.stamp.nanosec) * 1e-9


def set_stamp(header: Any, time_s: float) -> None:
    ns = round(time_s * 1e9)
    header.stamp.sec, header.stamp.nanosec = ns // 1_000_000_000, ns % 1_000_000_000


def image_array(msg: Any) -> np.ndarray:
    """An rgb8/bgr8 ``sensor_msgs/Image`` as (H, W, 3) uint8 RGB."""
    if msg.encoding not in ("rgb8", "bgr8"):
        raise JobFailed(f"image encoding must be rgb8 or bgr8, got {msg.encoding!r}")
    rows = np.frombuffer(bytes(msg.data), dtype=np.uint8).reshape(msg.height, msg.step)
    image = rows[:, : msg.width * 3].reshape(msg.height, msg.width, 3)
    return np.ascontiguousarray(image[..., ::-1] if msg.encoding == "bgr8" else image)


def camera_info_from_msg(msg: Any) -> CameraInfo:
    return CameraInfo(
        int(msg.width),
        int(msg.height),
        tuple(float(v) for v in msg.k),
        tuple(float(v) for v in msg.d),
        tuple(float(v) for v in msg.r),
        tuple(float(v) for v in msg.p),
        str(msg.distortion_model),
        str(msg.header.frame_id),
    )


def command_msg(values: Mapping[str, float], topics: Topics) -> Any:
    """A ``Float64MultiArray`` of ``values``, each dimension labelled with the robot's name."""
    std = ros_modules()[2]
    msg = std.Float64MultiArray()
    msg.layout.dim = [
        std.MultiArrayDimension(label=topics.robot_joint(n), size=1, stride=1) for n in values
    ]
    msg.data = [float(v) * topics.sign(n) for n, v in values.items()]
    return msg


def command_values(msg: Any, topics: Topics, joint_names: Sequence[str]) -> dict[str, float]:
    """A command's values by headsim's joint names (unlabelled: in ``joint_names`` order)."""
    labels = [d.label for d in msg.layout.dim]
    if not labels:
        labels = [topics.robot_joint(n) for n in joint_names[: len(msg.data)]]
    ours = {topics.robot_joint(n): n for n in joint_names}
    unknown = [label for label in labels if label not in ours]
    if unknown:
        raise JobFailed(f"a command names unknown joint {unknown[0]!r}")
    return {
        ours[label]: float(v) * topics.sign(ours[label])
        for label, v in zip(labels, msg.data, strict=True)
    }


class RosHead(RosServo):
    """A head on ROS 2 topics (see the module docstring); spins its node on a thread.

    ``belief``: what the head believes of its geometry; ``limits``: each joint's (low,
    high) range, rad; ``tolerance_rad``: how near its command a joint must be for a
    command to have ended, rad (default: half an encoder step with
    ``encoder_resolution_rad``, else 2e-3), and ``still_rad_s`` how slowly it must turn
    where the joint states give its rate.  For the servos
    (:class:`~headsim.head.servo_head.ServoHead`): ``encoder_resolution_rad``, one
    encoder step of its joints, rad; ``model``: the head's model (its neck); ``sink``:
    where its grabs are reported.
    """

    def __init__(
        self,
        joint_names: Sequence[str],
        topics: Topics | None = None,
        belief: HeadBelief | None = None,
        limits: Mapping[str, tuple[float, float]] | None = None,
        tolerance_rad: float | None = None,
        timeout_s: float = 30.0,
        node_name: str = "headsim_head",
        *,
        still_rad_s: float = 0.05,
        encoder_resolution_rad: float | None = None,
        model: HeadModel = PAPER,
        sink: EventSink = NO_EVENTS,
    ) -> None:
        rclpy, sensor, std, _ = ros_modules()
        self.topics = topics or Topics()
        self._names = tuple(joint_names)
        self._belief = belief or HeadBelief()
        self._init_servo(encoder_resolution_rad, limits or {}, model, sink)
        if tolerance_rad is None:
            tolerance_rad = 2e-3 if encoder_resolution_rad is None else encoder_resolution_rad / 2
        self.tolerance_rad = tolerance_rad
        self.still_rad_s = still_rad_s
        self.timeout_s = timeout_s
        self._own_context = not rclpy.ok()
        if self._own_context:
            rclpy.init()
        self.node = rclpy.create_node(node_name)
        self._changed = threading.Condition()
        self._arrivals = 0
        #: The stamp of the joint state that ended the last command, and the arrival
        #: number of each eye's last image grabbed: a grab takes images stamped at or after
        #: the one, arrived after the other.
        self._settled_s = -np.inf
        self._grabbed = [0, 0]
        #: The stamp of the newest joint state when the last command was published: the
        #: state that ends it is a later one.
        self._commanded_s = -np.inf
        #: Each eye's latest images: (arrival number, stamp in s, image).
        self._images: list[list[tuple[int, float, np.ndarray]]] = [[], []]
        self._infos: list[CameraInfo | None] = [None, None]
        self._joints: JointReading | None = None
        latched = latched_qos()
        for index in (0, 1):
            self.node.create_subscription(
                sensor.CameraInfo,
                self.topics.camera_infos[index],
                self._on_info(index),
                latched,
            )
            self.node.create_subscription(
                sensor.Image, self.topics.images[index], self._on_image(index), latched
            )
        self.node.create_subscription(
            sensor.JointState, self.topics.joint_states, self._on_joints, latched
        )
        self._position = self.node.create_publisher(
            std.Float64MultiArray, self.topics.position_commands, 10
        )
        self._velocity = self.node.create_publisher(
            std.Float64MultiArray, self.topics.velocity_commands, 10
        )
        self._executor = rclpy.executors.SingleThreadedExecutor()
        self._executor.add_node(self.node)
        self._spinner = threading.Thread(target=self._executor.spin, daemon=True)
        self._spinner.start()

    # -- subscriptions (on the spinner thread) ----------------------------------------
    def _on_info(self, index: int) -> Callable[[Any], None]:
        def handle(msg: Any) -> None:
            with self._changed:
                self._infos[index] = camera_info_from_msg(msg)
                self._changed.notify_all()

        return handle

    def _on_image(self, index: int) -> Callable[[Any], None]:
        def handle(msg: Any) -> None:
            image = image_array(msg)
            with self._changed:
                self._arrivals += 1
                kept = self._images[index]
                kept.append((self._arrivals, stamp_s(msg.header), image))
                del kept[:-8]
                self._changed.notify_all()

        return handle

    def _on_joints(self, msg: Any) -> None:
        ours = {self.topics.robot_joint(n): n for n in self._names}
        sign = self.topics.sign
        positions = {
            ours[n]: float(p) * sign(ours[n])
            for n, p in zip(msg.name, msg.position, strict=False)
            if n in ours
        }
        velocities = {
            ours[n]: float(v) * sign(ours[n])
            for n, v in zip(msg.name, msg.velocity, strict=False)
            if n in ours
        }
        with self._changed:
            self._joints = JointReading(stamp_s(msg.header), positions, velocities)
            self._arrivals += 1
            self._changed.notify_all()

    def _wait(self, ready: Callable[[], bool], what: str) -> None:
        with self._changed:
            if not self._changed.wait_for(ready, timeout=self.timeout_s):
                raise JobFailed(f"the ROS 2 head: no {what} within {self.timeout_s} s")

    # -- the Head interface --------------------------------------------------------------
    @property
    def joint_names(self) -> tuple[str, ...]:
        return self._names

    def joint_limits(self, joint: str) -> tuple[float, float]:
        return self._limits.get(joint, (-np.inf, np.inf))

    @property
    def belief(self) -> HeadBelief:
        return self._belief

    def camera_infos(self) -> tuple[CameraInfo, CameraInfo]:
        self._wait(lambda: None not in self._infos, "camera info")
        left, right = self._infos
        assert left is not None and right is not None
        return left, right

    def now(self) -> float:
        """The latest joint state's stamp (the head's clock), s."""
        return self.read_joints().time_s

    def read_joints(self) -> JointReading:
        self._wait(lambda: self._joints is not None, f"joint states on {self.topics.joint_states}")
        assert self._joints is not None
        return self._joints

    def _publish_position(self, positions_rad: Mapping[str, float]) -> None:
        """Publish a position command, without waiting."""
        with self._changed:
            self._commanded_s = -np.inf if self._joints is None else self._joints.time_s
        self._position.publish(command_msg(positions_rad, self.topics))

    def _await_position(self, positions_rad: Mapping[str, float]) -> JointReading:
        """Wait for a joint state stamped after the last command with every named joint
        within ``tolerance_rad`` of ``positions_rad``; grabs then take images stamped at
        or after it."""

        def off(reading: JointReading) -> list[str]:
            """The named joints not within tolerance, or still turning faster than
            ``still_rad_s`` (where the joint states give rates), each with where it is."""
            at, rate = reading.positions_rad, reading.velocities_rad_s
            away = [
                f"{n} at {at[n]!r} rad" if n in at else f"{n} not in the joint states"
                for n, v in positions_rad.items()
                if not abs(at.get(n, np.inf) - v) <= self.tolerance_rad
            ]
            moving = [
                f"{n} still turning at {rate[n]!r} rad/s"
                for n in positions_rad
                if n in rate and not abs(rate[n]) <= self.still_rad_s
            ]
            return away + moving

        def new() -> JointReading | None:
            j = self._joints
            return j if j is not None and j.time_s > self._commanded_s else None

        with self._changed:
            if not self._changed.wait_for(
                lambda: (j := new()) is not None and not off(j), timeout=self.timeout_s
            ):
                latest = new()
                why = (
                    f"no joint state on {self.topics.joint_states} since the command"
                    if latest is None
                    else "; ".join(off(latest))
                )
                raise JobFailed(
                    f"the ROS 2 head: not within {self.tolerance_rad:g} rad of "
                    f"{dict(positions_rad)} and still after {self.timeout_s} s: {why}"
                )
            assert self._joints is not None
            self._settled_s = self._joints.time_s
            return self._joints

    def command_position(self, positions_rad: Mapping[str, float]) -> None:
        """Publish the command and wait until every named joint is within tolerance of it."""
        self._publish_position(positions_rad)
        self._await_position(positions_rad)

    def command_velocity(self, velocities_rad_s: Mapping[str, float], duration_s: float) -> None:
        """Publish the rates, wait ``duration_s`` (wall clock), then publish zeros."""
        self._velocity.publish(command_msg(velocities_rad_s, self.topics))
        time.sleep(duration_s)
        self._velocity.publish(command_msg(dict.fromkeys(velocities_rad_s, 0.0), self.topics))
        with self._changed:
            self._joints = None
        self._wait(lambda: self._joints is not None, "joint states after the motion")
        with self._changed:
            assert self._joints is not None
            self._settled_s = self._joints.time_s

    def _fresh(self, index: int) -> list[tuple[int, float, np.ndarray]]:
        """Eye ``index``'s images taken since the last command settled (stamped at or after
        the joint state that ended it) and arrived after its last grab."""
        return [
            image
            for image in self._images[index]
            if image[0] > self._grabbed[index] and image[1] >= self._settled_s
        ]

    def _next_image(self, camera: int) -> np.ndarray:
        """Camera 1 or 2's newest fresh image (waiting for one)."""
        index = camera - 1
        self._wait(lambda: bool(self._fresh(index)), f"a new image from camera {camera}")
        with self._changed:
            arrival, _, image = self._fresh(index)[-1]
            self._grabbed[index] = arrival
        return image

    def grab_stereo(self) -> StereoFrame:
        """The newest fresh left image, with the fresh right image nearest it in time
        (waiting for one from each eye)."""
        left_info, right_info = self.camera_infos()
        self._wait(
            lambda: bool(self._fresh(0)) and bool(self._fresh(1)), "new images from both eyes"
        )
        with self._changed:
            _, left_s, left = self._fresh(0)[-1]
            _, right_s, right = min(self._fresh(1), key=lambda image: abs(image[1] - left_s))
            self._grabbed = [self._arrivals, self._arrivals]
        self._taken = [left, right]
        self._taken_image(1, left, ImageKind.FULL)
        self._taken_image(2, right, ImageKind.FULL)
        return StereoFrame(
            StampedImage(left_s, left, left_info), StampedImage(right_s, right, right_info)
        )

    def close(self) -> None:
        """Stop spinning (the spinner thread ended: one left running aborts the
        interpreter's exit) and destroy the node."""
        rclpy = ros_modules()[0]
        self._executor.shutdown()
        self._spinner.join(timeout=self.timeout_s)
        self.node.destroy_node()
        if self._own_context and rclpy.ok():
            rclpy.shutdown()


__all__ = ["RosHead", "binned", "command_msg", "command_values", "image_array", "ros_modules"]
