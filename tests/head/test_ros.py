"""The ROS 2 head end to end on the loopback: a real ROS 2 node (another process) serves
the simulator's images, camera infos and joint states and takes forward-controller
commands; the marker procedure, Model 2 (the eye servo's windows and previews) and
Model 1 (the neck servo) run through :class:`RosHead` and get the estimates they get on
the simulator directly, bit for bit.  Needs the ``ros`` extra: without rclpy the test says it did not run."""

from __future__ import annotations

import os
import random
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge
from headsim.active.model1 import measure_model1
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.errors import JobFailed
from headsim.head.ros_head import RosHead, binned
from headsim.head.servo_head import NoTruth, ServoHead
from headsim.head.sim_head import SimHead
from headsim.head.stereo_look import look_and_estimate
from headsim.paper import INITIAL_DIRECTIONS_RAD
from headsim.runs.targets import marker_target
from headsim.sim.events import ImageKind, ImageTaken, RenderCounts
from headsim.sim.joints import JointLimitError
from headsim.sim.names import MARKER_COLOURS
from headsim.sim.render import Window
from headsim.sim.settings import HeadSettings, SettingsError, paper_head
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

#: The simulated paper head as a ROS 2 node, sending its last messages again every 0.2 s
#: (an eye grabbed again where it was last grabbed gets the resent image).
NODE = textwrap.dedent(
    """
    import rclpy
    from headsim.head.ros_bridge import SimBridge
    from headsim.head.sim_head import SimHead
    from headsim.sim.settings import paper_head
    from headsim.sim.simulator import HeadSim

    rclpy.init()
    with HeadSim("default", paper_head()) as sim:
        bridge = SimBridge(SimHead(sim), resend_s=0.2)
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


def _serve(ros_env: dict[str, str], node_code: str) -> Iterator[None]:
    node = subprocess.Popen(
        [sys.executable, "-c", node_code], env=ros_env, stdout=subprocess.PIPE, text=True
    )
    try:
        assert node.stdout is not None and node.stdout.readline().strip() == "ready"
        yield
    finally:
        node.terminate()
        node.wait(timeout=30)
        assert node.stdout is not None
        node.stdout.close()


@pytest.fixture()
def sim_node(ros_env: dict[str, str]) -> Iterator[None]:
    """The simulated paper head served as a ROS 2 node (:data:`NODE`) in another process."""
    yield from _serve(ros_env, NODE)


#: A robot whose eye joint has its own name and turns the other way (positive outward).
ROBOT_TOPICS = 'Topics(joints={"eye": "l_eye_pan"}, signs={"eye": -1.0})'


@pytest.fixture()
def robot_node(ros_env: dict[str, str]) -> Iterator[None]:
    """The same node, publishing and taking the eye as :data:`ROBOT_TOPICS`' robot does."""
    code = NODE.replace(
        "SimBridge(SimHead(sim), resend_s=0.2)",
        f"SimBridge(SimHead(sim), {ROBOT_TOPICS}, resend_s=0.2)",
    ).replace("import rclpy\n", "import rclpy\nfrom headsim.head.mcap_log import Topics\n")
    assert ROBOT_TOPICS in code and "import Topics" in code
    yield from _serve(ros_env, code)


def test_a_robot_whose_eye_turns_the_other_way_is_driven_in_headsims_sense(
    robot_node: None,
) -> None:
    """The mapping's names and signs (``Topics``): the robot's ``l_eye_pan`` is headsim's
    eye reversed; through them the marker procedure measures what it measures on the
    simulator, bit for bit, and a head told no sign reads the eye negated."""
    from headsim.head.mcap_log import Topics

    with HeadSim("default", paper_head()) as sim:
        direct = look_and_estimate(SimHead(sim), POSES, MARKER_COLOURS)
    topics = Topics(joints={"eye": "l_eye_pan"}, signs={"eye": -1.0})
    head = RosHead(("neck_yaw", "neck_pitch", "eye"), topics, timeout_s=60.0)
    unsigned = RosHead(
        ("neck_yaw", "neck_pitch", "eye"),
        Topics(joints={"eye": "l_eye_pan"}),
        timeout_s=60.0,
        node_name="headsim_unsigned",
    )
    try:
        through_ros = look_and_estimate(head, POSES, MARKER_COLOURS)
        eye = head.read_joints().positions_rad["eye"]
        assert eye == pytest.approx(POSES[-1]["eye"], abs=2e-3)
        deadline = time.monotonic() + 10.0  # its spinner may be a message behind
        while unsigned.read_joints().positions_rad["eye"] != -eye:
            assert time.monotonic() < deadline, "the unsigned head never read -eye"
            time.sleep(0.01)
    finally:
        unsigned.close()
        head.close()
    for a, b in zip(direct, through_ros, strict=True):
        assert a.name == b.name
        assert a.point_head_m.tobytes() == b.point_head_m.tobytes()


def test_a_procedure_through_ros2_matches_the_simulator(sim_node: None) -> None:
    with HeadSim("default", paper_head()) as sim:
        direct = look_and_estimate(SimHead(sim), POSES, MARKER_COLOURS)
    head = RosHead(("neck_yaw", "neck_pitch", "eye"), timeout_s=60.0)
    try:
        through_ros = look_and_estimate(head, POSES, MARKER_COLOURS)
        before = head.read_joints().positions_rad["eye"]
        head.command_velocity({"eye": -0.1}, 0.3)
        after = head.read_joints().positions_rad["eye"]
        # The servos' grabs of one eye: a window of the pair just grabbed, its whole
        # image again, then each eye's next image (the node's resend of the same pair)
        # binned and windowed, cropped and binned here.
        grabs, counted = head.render_count, head.render_counts
        frame = head.grab_stereo()
        retaken = head.render_window(1, WINDOW, retake=True)
        whole = head.retake(2)
        preview = head.render_preview(2, 4)
        window = head.render_window(1, WINDOW)
        grabs, counted = head.render_count - grabs, head.render_counts - counted
    finally:
        head.close()
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
    assert counted == RenderCounts(images=2, windows=1, retakes=2, previews=1)
    # 0.1 rad/s for 0.3 s of wall clock, turned on the node's 20 ms timer
    assert -0.06 < after - before < -0.01
    assert np.isfinite(after)


class _Taken:
    """The images a head reports to its sink."""

    def __init__(self) -> None:
        self.images: list[ImageTaken] = []

    def emit(self, event: object) -> None:
        if isinstance(event, ImageTaken):
            self.images.append(event)


def _servo_head(
    settings: HeadSettings, limits: dict[str, tuple[float, float]], **options: Any
) -> RosHead:
    """A RosHead on the node's topics, given what the simulated head's owner would give:
    its belief, its joints' limits and its encoder resolution."""
    return RosHead(
        ("neck_yaw", "neck_pitch", "eye"),
        belief=settings.believed,
        limits=limits,
        timeout_s=60.0,
        encoder_resolution_rad=settings.encoder_resolution_rad,
        **options,
    )


def test_model2_through_ros2_measures_what_it_measures_on_the_simulator(sim_node: None) -> None:
    """Model 2 on each marker through RosHead, a ServoHead from what the robot publishes
    (CameraInfo, joint states) and what its owner gives (encoder resolution, limits,
    belief), against Model 2 on a SimHead over the same head and scene: bit for bit.

    The images it detects in are the same pixels: a window is cropped here from the
    node's whole frame, and the simulator renders a window as its whole frame's crop
    (the paper head has no image noise, whose frame counter would differ: the node takes
    both eyes' frames after every command).  The previews are not (binned here, a
    low-resolution readout there) but only place the windows."""
    settings = paper_head()
    knowledge = HeadKnowledge(alpha_e=INITIAL_DIRECTIONS_RAD)
    with HeadSim("default", settings) as sim:
        direct_head = SimHead(sim)
        limits = {motor: direct_head.joint_range(motor) for motor in direct_head.motors}
        direct_servo = EyeServo(direct_head)
        targets = [marker_target(body, body) for body in MARKER_COLOURS]
        direct = [measure_model2(direct_head, direct_servo, t, knowledge) for t in targets]
        direct_renders = sim.render_count
    missing = [name for name in dir(ServoHead) if name[0] != "_" and not hasattr(RosHead, name)]
    assert not missing  # the whole ServoHead interface
    taken = _Taken()
    head = _servo_head(settings, limits, sink=taken)
    # The scoring asks the target's truth of the head: record when (in images grabbed).
    asked: list[tuple[str, int]] = []

    def scored(body: str) -> Callable[[ServoHead], np.ndarray]:
        def truth_world(measured: ServoHead) -> np.ndarray:
            asked.append((body, measured.render_count))
            return measured.truth.position(body)

        return truth_world

    try:
        servo = EyeServo(head)
        through_ros, grabbed = [], []
        for body in MARKER_COLOURS:
            target = replace(marker_target(body, body), truth_world=scored(body))
            through_ros.append(measure_model2(head, servo, target, knowledge))
            grabbed.append((body, head.render_count))
        counts = head.render_counts
        specified = head.settings
        # A command the joint states cannot show (0.1 rad is between encoder steps) with a
        # tolerance below a step: settle gives up naming the joint and where it is.
        head.tolerance_rad, head.timeout_s = 1e-12, 1.0
        head.command(eye=0.1)
        with pytest.raises(JobFailed, match=r"after 1.0 s: eye at 0\.09\d+ rad$"):
            head.settle()
    finally:
        head.close()
    # Its specification: the node's CameraInfo, and what it was given.
    assert specified.encoder_resolution_rad == settings.encoder_resolution_rad
    assert specified.believed == settings.believed
    for ours, served in zip(specified.cameras, settings.cameras, strict=True):
        assert ours.pinhole() == served.pinhole()
    assert [m.ok for m in direct] == [m.ok for m in through_ros] == [True] * 3
    for a, b in zip(direct, through_ros, strict=True):
        assert a.estimate_head_m.tobytes() == b.estimate_head_m.tobytes()
        assert a.covariance_head_m2.tobytes() == b.covariance_head_m2.tobytes()
        assert a.details == b.details and a.renders == b.renders
        assert np.isnan(b.truth_head_m).all() and np.isfinite(a.truth_head_m).all()
    # The same looks: windows placed by previews, as on the simulator.
    assert counts.total == head.render_count == direct_renders
    assert (
        counts.windows
        == servo.looker.counts.window_renders
        == direct_servo.looker.counts.window_renders
        > 0
    )
    assert (
        counts.previews == servo.looker.counts.previews == direct_servo.looker.counts.previews > 0
    )
    assert len(taken.images) == counts.total  # each reported to the head's sink
    assert sum(e.kind is ImageKind.PREVIEW for e in taken.images) == counts.previews
    # The truth was asked once per target, by the scoring after its last image (and
    # found none); measuring never asked it (NoTruth would have ended the run).
    assert asked == grabbed


def test_model1_through_ros2_moves_the_neck_as_on_the_simulator(sim_node: None) -> None:
    """Model 1 (the neck servo: neck yaw, neck pitch and the eye together) on each marker
    through RosHead and on the simulator directly: bit for bit, in H and, through the
    neck encoders, in W."""

    settings = paper_head()
    knowledge = HeadKnowledge(alpha_e=INITIAL_DIRECTIONS_RAD)
    targets = [marker_target(body, body) for body in MARKER_COLOURS]
    with HeadSim("default", settings) as sim:
        direct_head = SimHead(sim)
        limits = {motor: direct_head.joint_range(motor) for motor in direct_head.motors}
        servo = NeckServo(direct_head)
        direct = [measure_model1(direct_head, servo, t, knowledge) for t in targets]
    head = _servo_head(settings, limits)
    try:
        servo = NeckServo(head)
        through_ros = [measure_model1(head, servo, t, knowledge) for t in targets]
        neck = head.neck_encoders()
    finally:
        head.close()
    assert neck != (0.0, 0.0)  # the neck turned
    assert [m.ok for m in direct] == [m.ok for m in through_ros] == [True] * 3
    for a, b in zip(direct, through_ros, strict=True):
        assert a.estimate_head_m.tobytes() == b.estimate_head_m.tobytes()
        assert a.estimate_world_m.tobytes() == b.estimate_world_m.tobytes()
        assert a.details == b.details and a.renders == b.renders


def test_a_script_that_grabs_and_closes_exits_cleanly(
    sim_node: None, ros_env: dict[str, str]
) -> None:
    """close() ends the spinner thread: one left spinning aborts the interpreter's exit."""
    script = (
        "from headsim.head.ros_head import RosHead\n"
        "head = RosHead(('neck_yaw', 'neck_pitch', 'eye'), timeout_s=60.0)\n"
        "print(head.grab_stereo().left.image.shape)\n"
        "head.close()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], env=ros_env, capture_output=True, text=True, timeout=120
    )
    assert (done.returncode, done.stdout, done.stderr) == (0, "(480, 640, 3)\n", "")


def test_a_ros2_head_says_what_it_lacks(ros_env: dict[str, str]) -> None:
    """No robot on the topics, no encoder resolution, limits for the eye only."""
    head = RosHead(("neck_pitch", "eye"), limits={"eye": (-0.7, 0.7)}, timeout_s=0.3)
    try:
        with pytest.raises(SettingsError, match="needs its encoder_resolution_rad"):
            head.settings  # noqa: B018
        with pytest.raises(NoTruth):
            head.truth  # noqa: B018
        with pytest.raises(SettingsError, match="no limits for motor 'neck_pitch'"):
            head.joint_range("neck_pitch")
        with pytest.raises(JointLimitError, match=r"command 0\.8 rad for eye is outside"):
            head.command(eye=0.8)
        with pytest.raises(SettingsError, match="no motor 'neck_yaw'"):
            head.command(neck_yaw=0.1)
        with pytest.raises(JobFailed, match="nothing grabbed from camera 2 to retake"):
            head.retake(2)
        head.command(eye=0.1)
        with pytest.raises(JobFailed, match="no joint state on /joint_states since the command"):
            head.settle()
        assert head.render_count == 0
    finally:
        head.close()


def test_binning_averages_each_block_and_refuses_a_size_it_does_not_divide() -> None:
    image = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    preview = binned(image, 2)
    assert preview.shape == (2, 3, 3) and preview.dtype == np.uint8
    block = image[2:4, 2:4].astype(float).mean(axis=(0, 1))
    assert np.array_equal(preview[1, 1], np.rint(block).astype(np.uint8))
    with pytest.raises(ValueError, match="binning 4 must divide the 6x4 image"):
        binned(image, 4)


def test_a_command_ends_only_once_the_joint_has_stopped(ros_env: dict[str, str]) -> None:
    """A joint state at the command but still turning (a robot overshooting) does not end
    it: settle names the rate, and the next state, at rest, ends it."""
    import rclpy

    from headsim.head.ros_head import latched_qos, ros_modules, set_stamp

    sensor = ros_modules()[1]
    head = RosHead(("eye",), limits={"eye": (-0.7, 0.7)}, timeout_s=10.0)
    robot = rclpy.create_node("headsim_test_robot_eye")
    states = robot.create_publisher(sensor.JointState, "/joint_states", latched_qos())

    def publish(time_s: float, position_rad: float, rate_rad_s: float) -> None:
        msg = sensor.JointState()
        set_stamp(msg.header, time_s)
        msg.name, msg.position, msg.velocity = ["eye"], [position_rad], [rate_rad_s]
        states.publish(msg)

    try:
        publish(1.0, 0.0, 0.0)
        assert head.read_joints().time_s == 1.0
        head.command(eye=0.1)
        publish(2.0, 0.1, 0.3)
        head.timeout_s = 1.0
        with pytest.raises(JobFailed, match=r"after 1.0 s: eye still turning at 0\.3 rad/s$"):
            head.settle()
        head.timeout_s = 10.0
        publish(3.0, 0.1, 0.0)
        reading = head.settle()
        assert (reading.time_s, reading.velocities_rad_s["eye"]) == (3.0, 0.0)
    finally:
        robot.destroy_node()
        head.close()
