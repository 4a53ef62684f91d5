"""A live head over ROS 2 (the ``ros`` extra): :class:`RosHead` is the
:class:`~headsim.head.interface.Head` interface on a robot's topics and its
``ros2_control`` forward controllers.

It subscribes to each eye's ``sensor_msgs/Image`` (rgb8 or bgr8) and ``CameraInfo``
and to ``JointState``; it commands through ``std_msgs/Float64MultiArray`` on the
forward position and velocity controllers' ``~/commands`` (values in
``joint_names`` order, each dimension labelled with the joint's name).  A position
command returns once the joint states are within ``tolerance_rad`` of it; a grab
waits for a pair of images that arrived after the last command settled (Ca1's with
Ca2's nearest in time).  The servos' grabs of one eye (:class:`~headsim.head.servo_head.ServoHead`'s
``render``, ``render_window``, ``render_preview``, ``retake``) take that eye's next such
image and crop its region of interest or bin it on the host, as for a camera driver
without hardware ROI or binning.  Topic and joint names: a
:class:`~headsim.head.mcap_log.Topics` (the mapping file's).  Installing: see
docs/how-to/real-head.md.
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
from headsim.sim.render import Window
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


def binned(image: np.ndarray, binning: int) -> np.ndarray:
    """``image`` (H, W, 3) uint8 binned ``binning`` x ``binning``: each pixel the rounded
    mean of its block, (H/b, W/b, 3) uint8."""
    height, width = image.shape[:2]
    if binning < 1 or height % binning or width % binning:
        raise ValueError(f"binning {binning} must divide the {width}x{height} image")
    blocks = image.reshape(height // binning, binning, width // binning, binning, -1)
    return np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8)


def command_msg(values: Mapping[str, float], topics: Topics) -> Any:
    """A ``Float64MultiArray`` of ``values``, each dimension labelled with the robot's name."""
    std = ros_modules()[2]
    msg = std.Float64MultiArray()
    msg.layout.dim = [
        std.MultiArrayDimension(label=topics.robot_joint(n), size=1, stride=1) for n in values
    ]
    msg.data = [float(v) for v in values.values()]
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
    return {ours[label]: float(v) for label, v in zip(labels, msg.data, strict=True)}


class RosHead:
    """A head on ROS 2 topics (see the module docstring); spins its node on a thread."""

    def __init__(
        self,
        joint_names: Sequence[str],
        topics: Topics | None = None,
        belief: HeadBelief | None = None,
        limits: Mapping[str, tuple[float, float]] | None = None,
        tolerance_rad: float = 2e-3,
        timeout_s: float = 30.0,
        node_name: str = "headsim_head",
    ) -> None:
        rclpy, sensor, std, _ = ros_modules()
        self.topics = topics or Topics()
        self._names = tuple(joint_names)
        self._belief = belief or HeadBelief()
        self._limits = dict(limits or {})
        self.tolerance_rad = tolerance_rad
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
        #: Each eye's image last grabbed (a retake's), and the grabs so far.
        self._taken: list[np.ndarray | None] = [None, None]
        self._grabs = 0
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
        positions = {
            ours[n]: float(p) for n, p in zip(msg.name, msg.position, strict=False) if n in ours
        }
        velocities = {
            ours[n]: float(v) for n, v in zip(msg.name, msg.velocity, strict=False) if n in ours
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

    def command_position(self, positions_rad: Mapping[str, float]) -> None:
        """Publish the command and wait until every named joint is within tolerance of it."""
        with self._changed:
            self._joints = None
        self._position.publish(command_msg(positions_rad, self.topics))

        def there() -> bool:
            j = self._joints
            return j is not None and all(
                abs(j.positions_rad.get(n, np.inf) - v) <= self.tolerance_rad
                for n, v in positions_rad.items()
            )

        self._wait(there, f"joints reaching {dict(positions_rad)}")
        with self._changed:
            assert self._joints is not None
            self._settled_s = self._joints.time_s

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
        self._taken, self._grabs = [left, right], self._grabs + 2
        return StereoFrame(
            StampedImage(left_s, left, left_info), StampedImage(right_s, right, right_info)
        )

    # -- the servos' grabs of one eye (ServoHead's) --------------------------------------
    @property
    def render_count(self) -> int:
        """Images grabbed so far: each eye's of a stereo grab, frames, windows, retakes and
        previews, each one."""
        return self._grabs

    def _grab(self, camera: int) -> np.ndarray:
        """Camera 1 or 2's newest fresh image (waiting for one)."""
        index = camera - 1
        self._wait(lambda: bool(self._fresh(index)), f"a new image from camera {camera}")
        with self._changed:
            arrival, _, image = self._fresh(index)[-1]
            self._grabbed[index] = arrival
        self._taken[index], self._grabs = image, self._grabs + 1
        return image

    def _retaken(self, camera: int) -> np.ndarray:
        image = self._taken[camera - 1]
        if image is None:
            raise JobFailed(f"the ROS 2 head: nothing grabbed from camera {camera} to retake")
        self._grabs += 1
        return image

    def render(self, camera: int) -> np.ndarray:
        """Camera 1 or 2's next whole image, (H, W, 3) uint8 RGB."""
        return self._grab(camera)

    def retake(self, camera: int) -> np.ndarray:
        """The whole image camera 1 or 2 last gave (the same exposure)."""
        return self._retaken(camera)

    def render_window(self, camera: int, window: Window, retake: bool = False) -> np.ndarray:
        """Only ``window`` of camera 1 or 2's next image (``retake``: of its last), cropped
        here, (h, w, 3) uint8."""
        image = self._retaken(camera) if retake else self._grab(camera)
        return np.ascontiguousarray(image[window.y0 : window.y1, window.x0 : window.x1])

    def render_preview(self, camera: int, binning: int) -> np.ndarray:
        """Camera 1 or 2's next image binned ``binning`` x ``binning`` here (:func:`binned`)."""
        return binned(self._grab(camera), binning)

    def close(self) -> None:
        rclpy = ros_modules()[0]
        self._executor.shutdown()
        self.node.destroy_node()
        if self._own_context and rclpy.ok():
            rclpy.shutdown()


__all__ = ["RosHead", "binned", "command_msg", "command_values", "image_array", "ros_modules"]
