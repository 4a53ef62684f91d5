"""The ROS 2 head end to end on the loopback: a real ROS 2 node (another process) serves
the simulator's images, camera infos and joint states and takes forward-controller
commands; the marker procedure runs through :class:`RosHead` and gets the estimates it
gets on the simulator directly, bit for bit.  Needs the ``ros`` extra: without rclpy
the test says it did not run."""

from __future__ import annotations

import os
import random
import subprocess
import sys
import textwrap
from collections.abc import Iterator

import numpy as np
import pytest

from headsim.head.ros_head import binned
from headsim.head.sim_head import SimHead
from headsim.head.stereo_look import look_and_estimate
from headsim.sim.names import MARKER_COLOURS
from headsim.sim.render import Window
from headsim.sim.settings import paper_head
from headsim.sim.simulator import HeadSim

pytestmark = [
    pytest.mark.e2e,
    # the ROS 2 wheels' message generator imports lark-parser 0.12, which imports sre_parse and sre_constants
    pytest.mark.filterwarnings(
        "ignore:module 'sre_(parse|constants)' is deprecated:DeprecationWarning"
    ),
]

POSES = ({"eye": 0.0}, {"eye": 0.06}, {"eye": 0.1})
#: A region of interest of camera 1's 640 x 480 image.
WINDOW = Window(200, 150, 64, 48)

NODE = textwrap.dedent(
    """
    import rclpy
    from headsim.head.ros_bridge import SimBridge
    from headsim.head.sim_head import SimHead
    from headsim.sim.settings import paper_head
    from headsim.sim.simulator import HeadSim

    rclpy.init()
    with HeadSim("default", paper_head()) as sim:
        bridge = SimBridge(SimHead(sim))
        print("ready", flush=True)
        try:
            rclpy.spin(bridge.node)
        except Exception:
            pass
    """
)


@pytest.fixture()
def ros_env() -> Iterator[dict[str, str]]:
    try:
        import rclpy  # noqa: F401
        import sensor_msgs.msg  # noqa: F401
    except ImportError as err:
        pytest.skip(f"did not run: ROS 2 is not installed (pip install 'headsim[ros]'): {err}")
    env = {
        "ROS_DOMAIN_ID": str(random.randint(1, 100)),
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp",
    }
    saved = {key: os.environ.get(key) for key in env}
    os.environ.update(env)
    yield {**os.environ, **env}
    for key, value in saved.items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value


def test_a_procedure_through_ros2_matches_the_simulator(ros_env: dict[str, str]) -> None:
    from headsim.head.ros_head import RosHead

    with HeadSim("default", paper_head()) as sim:
        direct = look_and_estimate(SimHead(sim), POSES, MARKER_COLOURS)
    node = subprocess.Popen(
        [sys.executable, "-c", NODE], env=ros_env, stdout=subprocess.PIPE, text=True
    )
    try:
        assert node.stdout is not None and node.stdout.readline().strip() == "ready"
        head = RosHead(("neck_yaw", "neck_pitch", "eye"), timeout_s=60.0)
        try:
            through_ros = look_and_estimate(head, POSES, MARKER_COLOURS)
            before = head.read_joints().positions_rad["eye"]
            head.command_velocity({"eye": -0.1}, 0.3)
            after = head.read_joints().positions_rad["eye"]
            # The servos' grabs of one eye: a window of the pair just grabbed, its whole
            # image again, then each eye's next image (the node's resend of the same pair)
            # binned and windowed, cropped and binned here.
            grabs = head.render_count
            frame = head.grab_stereo()
            retaken = head.render_window(1, WINDOW, retake=True)
            whole = head.retake(2)
            preview = head.render_preview(2, 4)
            window = head.render_window(1, WINDOW)
            grabs = head.render_count - grabs
        finally:
            head.close()
    finally:
        node.terminate()
        node.wait(timeout=30)
        assert node.stdout is not None
        node.stdout.close()
    assert len(through_ros) == len(direct) == len(POSES) * len(MARKER_COLOURS)
    for a, b in zip(direct, through_ros, strict=True):
        assert a.name == b.name and a.status == b.status == "ok" and a.uv_px == b.uv_px
        assert a.point_head_m.tobytes() == b.point_head_m.tobytes()
    crop = frame.left.image[WINDOW.y0 : WINDOW.y1, WINDOW.x0 : WINDOW.x1]
    assert retaken.shape == (WINDOW.height, WINDOW.width, 3)
    assert np.array_equal(retaken, crop) and np.array_equal(window, crop)
    assert np.array_equal(whole, frame.right.image)
    assert preview.shape == (120, 160, 3) and np.array_equal(preview, binned(whole, 4))
    assert grabs == 6  # the pair's two images, then one each
    # 0.1 rad/s for 0.3 s of wall clock, turned on the node's 20 ms timer
    assert -0.06 < after - before < -0.01
    assert np.isfinite(after)


def test_binning_averages_each_block_and_refuses_a_size_it_does_not_divide() -> None:
    image = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    preview = binned(image, 2)
    assert preview.shape == (2, 3, 3) and preview.dtype == np.uint8
    block = image[2:4, 2:4].astype(float).mean(axis=(0, 1))
    assert np.array_equal(preview[1, 1], np.rint(block).astype(np.uint8))
    with pytest.raises(ValueError, match="binning 4 must divide the 6x4 image"):
        binned(image, 4)
