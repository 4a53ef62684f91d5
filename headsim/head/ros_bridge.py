"""The simulator as a ROS 2 node: a :class:`~headsim.head.sim_head.SimHead` publishing
what a robot's drivers publish and taking what its forward controllers take.

After each position command it applies (and once at the start), it publishes the
joint states, then each eye's CameraInfo and image (latched: transient local).
Velocity commands turn the joints on a ``period_s`` timer; when the rates return to
zero it publishes the joint states and a stereo pair.  Every ``resend_s`` it sends its
last messages again (a subscriber that missed one is not left waiting).  Stamps are
the simulated clock's.  ``python -m headsim.head.ros_bridge`` runs the paper head in the default
scene until interrupted.
"""

from __future__ import annotations

import threading
from typing import Any

from headsim.head.interface import JointReading, StereoFrame
from headsim.head.mcap_log import Topics
from headsim.head.ros_head import command_values, latched_qos, ros_modules, set_stamp
from headsim.head.sim_head import SimHead


class SimBridge:
    """A node serving ``head`` on ``topics`` (see the module docstring)."""

    def __init__(
        self,
        head: SimHead,
        topics: Topics | None = None,
        period_s: float = 0.02,
        resend_s: float = 1.0,
    ) -> None:
        rclpy, sensor, std, _ = ros_modules()
        self.head = head
        self.topics = topics or Topics()
        self.node = rclpy.create_node("headsim_sim_bridge")
        self._lock = threading.Lock()
        self._rates: dict[str, float] = {}
        latched = latched_qos()
        self._joint_pub = self.node.create_publisher(
            sensor.JointState, self.topics.joint_states, latched
        )
        self._image_pubs = [
            self.node.create_publisher(sensor.Image, topic, latched) for topic in self.topics.images
        ]
        self._info_pubs = [
            self.node.create_publisher(sensor.CameraInfo, topic, latched)
            for topic in self.topics.camera_infos
        ]
        self.node.create_subscription(
            std.Float64MultiArray, self.topics.position_commands, self._on_position, 10
        )
        self.node.create_subscription(
            std.Float64MultiArray, self.topics.velocity_commands, self._on_velocity, 10
        )
        self.period_s = period_s
        self.node.create_timer(period_s, self._tick)
        self.node.create_timer(resend_s, self._resend)
        self._last: list[tuple[Any, Any]] = []
        #: Commands applied, of each kind.
        self.applied = {"position": 0, "velocity": 0}
        self.publish_state()

    def _joint_msg(self, reading: JointReading) -> Any:
        sensor = ros_modules()[1]
        msg = sensor.JointState()
        set_stamp(msg.header, reading.time_s)
        msg.name = [self.topics.robot_joint(n) for n in reading.positions_rad]
        sign = self.topics.sign
        msg.position = [float(v) * sign(n) for n, v in reading.positions_rad.items()]
        msg.velocity = [
            float(reading.velocities_rad_s.get(n, 0.0)) * sign(n) for n in reading.positions_rad
        ]
        return msg

    def _publish_frame(self, frame: StereoFrame) -> None:
        sensor = ros_modules()[1]
        for index, stamped in enumerate((frame.left, frame.right)):
            frame_id = self.topics.optical_frames[index]
            info = stamped.camera_info
            info_msg = sensor.CameraInfo()
            set_stamp(info_msg.header, stamped.time_s)
            info_msg.header.frame_id = frame_id
            info_msg.width, info_msg.height = info.width, info.height
            info_msg.distortion_model = info.distortion_model
            info_msg.d, info_msg.k, info_msg.r, info_msg.p = (
                list(info.D),
                list(info.K),
                list(info.R),
                list(info.P),
            )
            self._send(self._info_pubs[index], info_msg)
            image = sensor.Image()
            set_stamp(image.header, stamped.time_s)
            image.header.frame_id = frame_id
            image.height, image.width = stamped.image.shape[:2]
            image.encoding = "rgb8"
            image.step = image.width * 3
            image.data = stamped.image.tobytes()
            self._send(self._image_pubs[index], image)

    def _send(self, publisher: Any, msg: Any) -> None:
        publisher.publish(msg)
        self._last = [(p, m) for p, m in self._last if p is not publisher] + [(publisher, msg)]

    def _resend(self) -> None:
        with self._lock:
            for publisher, msg in self._last:
                publisher.publish(msg)

    def publish_state(self) -> None:
        """The joint states now, then a fresh stereo pair."""
        self._send(self._joint_pub, self._joint_msg(self.head.read_joints()))
        self._publish_frame(self.head.grab_stereo())

    def _on_position(self, msg: Any) -> None:
        values = command_values(msg, self.topics, self.head.joint_names)
        with self._lock:
            self.head.command_position(values)
            self.applied["position"] += 1
            self.publish_state()

    def _on_velocity(self, msg: Any) -> None:
        values = command_values(msg, self.topics, self.head.joint_names)
        with self._lock:
            self._rates.update(values)
            self.applied["velocity"] += 1
            if not any(self._rates.values()):
                self._rates.clear()
                self.publish_state()

    def _tick(self) -> None:
        with self._lock:
            if self._rates:
                self.head.command_velocity(self._rates, self.period_s)
                self._send(self._joint_pub, self._joint_msg(self.head.read_joints()))


def main() -> None:  # pragma: no cover - a long-running node
    from headsim.sim.settings import paper_head
    from headsim.sim.simulator import HeadSim

    rclpy = ros_modules()[0]
    rclpy.init()
    with HeadSim("default", paper_head()) as sim:
        bridge = SimBridge(SimHead(sim))
        try:
            rclpy.spin(bridge.node)
        except KeyboardInterrupt:
            pass
        finally:
            bridge.node.destroy_node()
            if rclpy.ok():
                rclpy.shutdown()


if __name__ == "__main__":
    main()


__all__ = ["SimBridge"]
