"""The simulated head: commands, settling, encoders, ground truth and images.

Frames (docs/concepts/frames.md): W world, H head, and per camera its OpenCV frame
(x right, y down, z along the optical axis).  Transforms are 4 x 4 homogeneous
matrices named ``dst_from_src``: ``p_world = world_from_head @ p_head``.

Settling has two modes.  ``"kinematic"`` (default) puts the joints exactly at
their commanded angles and runs forward kinematics: the paper's procedures
measure a head at rest, so this is exact, deterministic and costs nothing.
``"physics"`` drives the position actuators and steps the dynamics until the
joints are still (bounded; the outcome says why it stopped), for studies of
settling error and moving heads.

Joint errors (backlash, count error): :mod:`headsim.sim.joints`.  Every image
taken is reported to the simulator's event sink (:mod:`headsim.sim.events`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import mujoco
import numpy as np

from headsim.geometry.kinematics import eye_from_camera_rotation
from headsim.geometry.stereo_view import StereoView
from headsim.geometry.transforms import apply_transform, homogeneous, invert_transform
from headsim.sim import names
from headsim.sim.events import NO_EVENTS, EventSink, ImageKind, ImageTaken
from headsim.sim.heads import actuator_on, eye_motor_range
from headsim.sim.joints import (
    Commands,
    JointLimitError,
    SettleOutcome,
    SettleResult,
    true_targets,
)
from headsim.sim.model import CV_FROM_MJCAM, HEAD_PREFIX, BuiltModel, build_model
from headsim.sim.optics import camera_matrix, dist_coeffs, project_points
from headsim.sim.render import EyeRenderer, Window, context_key
from headsim.sim.settings import CameraSettings, HeadBelief, HeadSettings, SettingsError
from headsim.sim.textured_scene import RoomSpec

#: A camera: 1 or 2 (the paper's Ca1, Ca2), its MJCF name "cam1"/"cam2", or a names.Camera.
CameraId = int | str | names.Camera


class HeadSim:
    """A head in a scene: command joints, settle, read encoders, render, read truth.

    :class:`headsim.head.sim_head.SimHead` makes it a :class:`~headsim.head.interface.Head`;
    its truth channel is :attr:`truth` (itself: a simulator knows where everything is).
    """

    def __init__(
        self,
        scene: str | Path = "default",
        settings: HeadSettings | None = None,
        settle_mode: str = "kinematic",
        settle_tolerance_rad: float = 1e-6,
        max_settle_steps: int = 5000,
        sink: EventSink | None = None,
        room: RoomSpec | None = None,
    ) -> None:
        """``room``: a textured room put into ``scene`` (:mod:`headsim.sim.textured_scene`)."""
        if settle_mode not in ("kinematic", "physics"):
            raise SettingsError(
                f"settle_mode must be 'kinematic' or 'physics', got {settle_mode!r}"
            )
        self.settings = settings or HeadSettings()
        self.settle_mode = settle_mode
        self.settle_tolerance_rad = settle_tolerance_rad
        self.max_settle_steps = max_settle_steps
        #: Where this simulator reports every image it takes (and the servos and
        #: procedures working with it report theirs, unless given another sink).
        self.sink: EventSink = NO_EVENTS if sink is None else sink
        self.built: BuiltModel = build_model(scene, self.settings, room)
        self.model = self.built.model
        self.data = mujoco.MjData(self.model)
        #: The head's names as compiled into the scene (:mod:`headsim.sim.heads`).
        self.names = self.built.names
        mapping = self.names
        #: Each motor's joint, by motor: the neck's, "eye" (Ca1's eye: the one motor of
        #: coupled eyes) and, with independent eyes, "eye2" (Ca2's eye).
        self._motor_joint = {
            motor: joint
            for motor, joint in (
                ("neck_yaw", mapping.neck_yaw),
                ("neck_pitch", mapping.neck_pitch),
                ("eye", mapping.left_eye),
                ("eye2", mapping.right_eye if mapping.independent else None),
            )
            if joint is not None
        }
        self.motors = tuple(self._motor_joint)
        self._home = names.HOME if self.settings.head.is_paper else HEAD_PREFIX + names.HOME
        self._qadr = {joint: int(self.model.joint(joint).qposadr[0]) for joint in mapping.joints}
        self._dofadr = {joint: int(self.model.joint(joint).dofadr[0]) for joint in self._qadr}
        self._actuator = {
            motor: actuator_on(self.model, joint) for motor, joint in self._motor_joint.items()
        }
        #: The version and vergence actuators of eyes driven so ((H7)), else None.
        self._version_vergence = (
            (
                int(self.model.actuator(mapping.version).id),
                int(self.model.actuator(mapping.vergence).id),
            )
            if mapping.version is not None and mapping.vergence is not None
            else None
        )
        self._commands = Commands()
        #: Bodies placed so far (targets moved: earlier images are out of date).
        self.placements = 0
        self._renderer = EyeRenderer(
            self.model,
            self.settings.cameras,
            self.built.canvases,
            seed=self.settings.seed,
            key=context_key(str(scene), self.model),
            camera_names=mapping.cameras,
            supersample=self.settings.render.supersample,
        )
        self.reset()

    # -- lifecycle -------------------------------------------------------
    def reset(self) -> None:
        """Back to the ``home`` keyframe (all joints 0)."""
        key = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_KEY, self._home)
        if key >= 0:
            mujoco.mj_resetDataKeyframe(self.model, self.data, key)
        else:
            mujoco.mj_resetData(self.model, self.data)
        self._commands = Commands()
        mujoco.mj_forward(self.model, self.data)

    def close(self) -> None:
        """Free the OpenGL contexts."""
        self._renderer.close()

    def __enter__(self) -> HeadSim:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- commands ----------------------------------------------------------
    def joint_range(self, motor: str) -> tuple[float, float]:
        """Range of a motor's joint ("neck_yaw", "neck_pitch", "eye", "eye2"), or of a
        joint of the head by its MJCF name, rad.  With version and vergence actuators
        the eye motor's is its range as the counter-yaw (:func:`eye_motor_range`)."""
        if motor == "eye" and self._version_vergence is not None:
            return eye_motor_range(self.model, self.names)
        low, high = self.model.joint(self._joint_of(motor)).range
        return float(low), float(high)

    def _joint_of(self, motor: str) -> str:
        if motor in self._qadr:
            return motor
        try:
            return self._motor_joint[motor]
        except KeyError:
            raise SettingsError(
                f"this head has no motor {motor!r}; allowed: {', '.join(self.motors)}"
            ) from None

    def _checked(self, motor: str, angle: float) -> float:
        joint = self._joint_of(motor)
        if not math.isfinite(angle):
            raise JointLimitError(f"command for {joint} must be finite, got {angle}")
        low, high = self.joint_range(motor)
        if not low <= angle <= high:
            raise JointLimitError(
                f"command {angle:.6f} rad for {joint} is outside its range [{low}, {high}] rad"
            )
        return float(angle)

    def command(
        self,
        *,
        neck_yaw: float | None = None,
        neck_pitch: float | None = None,
        eye: float | None = None,
        eye2: float | None = None,
    ) -> None:
        """Set joint targets, rad.  ``eye``: the eye angle, positive inward: the one motor
        of coupled eyes, or both motors of independent eyes (counter-yaw); ``eye2``:
        Ca2's eye alone, on a head with independent eyes (then ``eye`` moves Ca1's alone)."""
        c = self._commands
        previous = {motor: getattr(c, motor) for motor in self.motors}
        if neck_yaw is not None:
            c.neck_yaw = self._checked("neck_yaw", neck_yaw)
        if neck_pitch is not None:
            c.neck_pitch = self._checked("neck_pitch", neck_pitch)
        if eye2 is not None:
            c.eye2 = self._checked("eye2", eye2)
        if eye is not None:
            c.eye = self._checked("eye", eye)
            if eye2 is None and "eye2" in self.motors:
                c.eye2 = self._checked("eye2", eye)
        if self._version_vergence is not None:
            self._check_version_vergence(c.eye, c.eye2)
        for motor, old in previous.items():
            new = getattr(c, motor)
            if new != old:
                c.approach[motor] = 1.0 if new > old else -1.0
        true = self._true_targets()
        for motor in self.motors:
            if self._actuator[motor] >= 0:
                self.data.ctrl[self._actuator[motor]] = true[motor]
        if self._version_vergence is not None:
            version, vergence = self._version_vergence
            self.data.ctrl[version] = (true["eye"] - true["eye2"]) / 2
            self.data.ctrl[vergence] = true["eye"] + true["eye2"]

    def _check_version_vergence(self, left: float, right: float) -> None:
        """Eyes driven by version and vergence ((H7)) reach only their actuators' ranges."""
        assert self._version_vergence is not None
        for actuator, value, what in zip(
            self._version_vergence,
            ((left - right) / 2, left + right),
            ("version (left - right) / 2", "vergence left + right"),
            strict=True,
        ):
            low, high = (float(v) for v in self.model.actuator_ctrlrange[actuator])
            if bool(self.model.actuator_ctrllimited[actuator]) and not low <= value <= high:
                raise JointLimitError(
                    f"eye commands {left:.6f}, {right:.6f} rad need a {what} of {value:.6f} rad, "
                    f"outside its range [{low}, {high}] rad"
                )

    def commanded(self) -> dict[str, float]:
        """Each motor's current command, rad."""
        return {motor: float(getattr(self._commands, motor)) for motor in self.motors}

    def command_eye_steps(self, steps: int) -> None:
        """Command the eye motor to a whole number of encoder steps."""
        self.command(eye=int(steps) * self.settings.encoder_resolution_rad)

    def move(self, **targets: float) -> SettleResult:
        """``command(**targets)`` then ``settle()``."""
        self.command(**targets)
        return self.settle()

    def _true_targets(self) -> dict[str, float]:
        """Where each motor's joint truly settles, rad, by motor name."""
        return true_targets(self.settings, self._commands, self.motors)

    def _targets(self) -> dict[str, float]:
        true = self._true_targets()
        targets = {self._motor_joint[motor]: angle for motor, angle in true.items()}
        if "eye2" not in true:  # coupled: Ca2's eye follows the one motor
            targets[self.names.right_eye] = true["eye"]
        return targets

    def settle(self) -> SettleResult:
        """Bring the joints to their targets (see the module docstring for modes)."""
        targets = self._targets()
        if self.settle_mode == "kinematic":
            for joint, angle in targets.items():
                self.data.qpos[self._qadr[joint]] = angle
                self.data.qvel[self._dofadr[joint]] = 0.0
            mujoco.mj_forward(self.model, self.data)
            return SettleResult(SettleOutcome.KINEMATIC, 0, 0.0)
        error = math.inf
        for step in range(1, self.max_settle_steps + 1):
            mujoco.mj_step(self.model, self.data)
            error = max(abs(self.data.qpos[self._qadr[j]] - a) for j, a in targets.items())
            speed = max(abs(self.data.qvel[self._dofadr[j]]) for j in targets)
            if error < self.settle_tolerance_rad and speed < self.settle_tolerance_rad * 10:
                mujoco.mj_forward(self.model, self.data)
                return SettleResult(SettleOutcome.SETTLED, step, float(error))
        mujoco.mj_forward(self.model, self.data)
        return SettleResult(SettleOutcome.TIMEOUT, self.max_settle_steps, float(error))

    def step(self, n: int = 1) -> None:
        """Advance the physics ``n`` steps with the current commands."""
        for _ in range(n):
            mujoco.mj_step(self.model, self.data)

    # -- encoders ----------------------------------------------------------
    def _quantise(self, angle: float) -> float:
        resolution = self.settings.encoder_resolution_rad
        return round(angle / resolution) * resolution

    def _read(self, motor: str, joint: str) -> float:
        """What a motor's encoder sees, rad, before quantisation: the joint, or with
        joint errors the motor shaft (its command), since the errors lie beyond it."""
        if self.settings.joint_errors:
            return float(getattr(self._commands, motor))
        return float(self.data.qpos[self._qadr[joint]])

    def eye_encoder(self) -> float:
        """Eye-motor encoder reading, rad, a whole multiple of the resolution (with
        independent eyes, Ca1's eye's)."""
        return self._quantise(self._read("eye", self.names.left_eye))

    def eye_encoders(self) -> tuple[float, float]:
        """Each eye's encoder reading (Ca1's, Ca2's), rad: the one motor's twice when the
        eyes are coupled."""
        if "eye2" not in self.motors:
            reading = self.eye_encoder()
            return reading, reading
        return self.eye_encoder(), self._quantise(self._read("eye2", self.names.right_eye))

    def eye_encoder_steps(self) -> int:
        """Eye-motor encoder reading, whole steps."""
        return round(self._read("eye", self.names.left_eye) / self.settings.encoder_resolution_rad)

    def encoder_steps(self, motor: str) -> int:
        """A motor's encoder reading ("neck_yaw", "neck_pitch", "eye", "eye2"), whole steps."""
        joint = self._joint_of(motor)
        return round(self._read(motor, joint) / self.settings.encoder_resolution_rad)

    def neck_encoders(self) -> tuple[float, float]:
        """Neck (yaw, pitch) encoder readings, rad, quantised like the eye encoder (a head
        with no neck yaw reads 0)."""
        yaw = self.names.neck_yaw
        return (
            0.0 if yaw is None else self._quantise(self._read("neck_yaw", yaw)),
            self._quantise(self._read("neck_pitch", self.names.neck_pitch)),
        )

    def joint_speeds(self) -> dict[str, float]:
        """Each motor's joint speed, rad/s (0 at rest; kinematic settling leaves it at rest)."""
        return {
            motor: float(self.data.qvel[self._dofadr[joint]])
            for motor, joint in self._motor_joint.items()
        }

    @property
    def belief(self) -> HeadBelief:
        """What the head believes of its own geometry (its design); see ``HeadSettings.believed``."""
        return self.settings.believed

    # -- ground truth ------------------------------------------------------
    @property
    def truth(self) -> HeadSim:
        """The truth channel (:class:`~headsim.head.interface.Truth`), for placing and scoring
        only: code that measures reaches truth through it alone, so a test can shut it."""
        return self

    def true_joint_angles(self) -> dict[str, float]:
        """True joint angles by joint name, rad (not quantised)."""
        return {joint: float(self.data.qpos[adr]) for joint, adr in self._qadr.items()}

    def camera_index(self, camera: CameraId) -> int:
        """Position in ``settings.cameras`` (0, 1) of camera 1 or 2 (the paper's Ca1, Ca2),
        its MJCF name or its :class:`~headsim.sim.names.Camera`."""
        try:
            return names.Camera.of(camera).index
        except ValueError as err:
            raise SettingsError(str(err)) from None

    def camera_settings(self, camera: CameraId) -> CameraSettings:
        return self.settings.cameras[self.camera_index(camera)]

    def world_from_head(self) -> np.ndarray:
        """Pose of H in W, 4 x 4 (eq. (1) of the paper)."""
        body = self.data.body(self.names.head_body)
        return homogeneous(body.xmat.reshape(3, 3), body.xpos)

    def world_from_camera(self, camera: CameraId) -> np.ndarray:
        """Pose of a camera's OpenCV frame in W, 4 x 4."""
        cam = self.data.camera(self.names.cameras[self.camera_index(camera)])
        return homogeneous(cam.xmat.reshape(3, 3) @ CV_FROM_MJCAM, cam.xpos)

    def head_from_camera(self, camera: CameraId) -> np.ndarray:
        """Pose of a camera's OpenCV frame in H, 4 x 4."""
        return invert_transform(self.world_from_head()) @ self.world_from_camera(camera)

    def frame_from_world(self, frame: str) -> np.ndarray:
        """Transform from W to ``frame``: "world", "head", "cam1" or "cam2"."""
        if frame == "world":
            return np.eye(4)
        if frame == "head":
            return invert_transform(self.world_from_head())
        if frame in names.CAMERAS:
            return invert_transform(self.world_from_camera(frame))
        raise SettingsError(
            f"unknown frame {frame!r}; allowed: world, head, {', '.join(names.CAMERAS)}"
        )

    def position(self, name: str, frame: str = "world") -> np.ndarray:
        """Position of a body or site named ``name`` in ``frame``, m."""
        if mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name) >= 0:
            p_world = self.data.body(name).xpos
        elif mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name) >= 0:
            p_world = self.data.site(name).xpos
        else:
            raise SettingsError(f"no body or site named {name!r} in this scene")
        return self.transform_points(p_world, "world", frame)[0]

    def transform(self, src: str, dst: str) -> np.ndarray:
        """``dst_from_src``, 4 x 4, between frames "world", "head", "cam1" and "cam2"."""
        return self.frame_from_world(dst) @ invert_transform(self.frame_from_world(src))

    def transform_points(self, points: np.ndarray, src: str, dst: str) -> np.ndarray:
        """Map points (N, 3) from frame ``src`` to frame ``dst``, m."""
        return apply_transform(self.transform(src, dst), points)

    def stereo_view(self) -> StereoView:
        """Both cameras' true intrinsics and poses, and the head's pose, as they are now."""
        return StereoView(
            cameras=(self.camera_settings(1).pinhole(), self.camera_settings(2).pinhole()),
            camera_from_world=(
                self.transform("world", names.CAMERAS[0]),
                self.transform("world", names.CAMERAS[1]),
            ),
            world_from_head=self.transform("head", "world"),
        )

    def stereo_views(self, eye_angles_rad: Sequence[float] = ()) -> tuple[StereoView, ...]:
        """The view from the current pose, then from each eye-encoder angle (rad, to the
        nearest step; neck still).  The eyes go back to their current step, and the first
        view is taken there (with joint errors, where they settle on the way back)."""
        turned = []
        if eye_angles_rad:
            resolution = self.settings.encoder_resolution_rad
            before = self.eye_encoder_steps()
            for angle in eye_angles_rad:
                self.command_eye_steps(round(angle / resolution))
                self.settle()
                turned.append(self.stereo_view())
            self.command_eye_steps(before)
            self.settle()
        return (self.stereo_view(), *turned)

    def set_body_pose(
        self,
        name: str,
        position_world_m: np.ndarray | Sequence[float],
        quat_world: np.ndarray | None = None,
    ) -> None:
        """Place a mocap body (a target) in the world; takes effect at once."""
        body_id = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        mocap_id = int(self.model.body_mocapid[body_id]) if body_id >= 0 else -1
        if mocap_id < 0:
            raise SettingsError(f"{name!r} is not a movable (mocap) body in this scene")
        self.placements += 1
        self.data.mocap_pos[mocap_id] = position_world_m
        if quat_world is not None:
            self.data.mocap_quat[mocap_id] = quat_world
        mujoco.mj_forward(self.model, self.data)

    def set_texture(self, name: str, rgb: np.ndarray) -> None:
        """Replace texture ``name``'s pixels with ``rgb`` ((height, width, 3) uint8, its size);
        the next images show it."""
        texture_id = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_TEXTURE, name)
        if texture_id < 0:
            raise SettingsError(f"no texture {name!r} in this scene")
        shape = (
            int(self.model.tex_height[texture_id]),
            int(self.model.tex_width[texture_id]),
            int(self.model.tex_nchannel[texture_id]),
        )
        if rgb.shape != shape or rgb.dtype != np.uint8:
            raise SettingsError(
                f"texture {name!r} takes {shape} uint8, got {rgb.shape} {rgb.dtype}"
            )
        start = int(self.model.tex_adr[texture_id])
        self.model.tex_data[start : start + rgb.size] = rgb.reshape(-1)
        self._renderer.texture_changed(texture_id)

    def camera_matrix(self, camera: CameraId) -> np.ndarray:
        """True intrinsic matrix K of a camera's output image, px."""
        return camera_matrix(self.camera_settings(camera))

    def dist_coeffs(self, camera: CameraId) -> np.ndarray:
        """True OpenCV distortion vector (k1, k2, 0, 0, 0)."""
        return dist_coeffs(self.camera_settings(camera))

    def project(self, points_world: np.ndarray, camera: CameraId) -> np.ndarray:
        """True pixel coordinates (N, 2) of world points in a camera's image (with distortion)."""
        cam_points = self.transform_points(
            points_world, "world", names.CAMERAS[self.camera_index(camera)]
        )
        return project_points(cam_points, self.camera_settings(camera))

    def effective_initial_direction(self, camera: CameraId, goal_u: float | None = None) -> float:
        """The eye's effective initial direction, rad (what Sec. V calibration finds).

        The horizontal angle, in the eye frame at eye angle 0, of the ray through
        the servo's goal column ``goal_u`` (default: the image centre's) at the
        image centre row, positive inward: the mount yaw plus the angle by which
        that column's ray is off the optical axis.  At the principal point's
        column it is the mount yaw, on every row.
        """
        return effective_initial_direction(self.settings, self.camera_index(camera), goal_u)

    # -- images ------------------------------------------------------------
    def render(self, camera: CameraId) -> np.ndarray:
        """The camera's current image, (H, W, 3) uint8, with its lens and noise."""
        index, before = self.camera_index(camera), self.rendered_frames
        image = self._renderer.render(self.data, index)
        self.sink.emit(ImageTaken(index + 1, image, ImageKind.FULL, self.rendered_frames - before))
        return image

    def retake(self, camera: CameraId) -> np.ndarray:
        """The whole image of the instant just taken as a window (same noise), counted."""
        index, before = self.camera_index(camera), self.rendered_frames
        image = self._renderer.render(self.data, index, retake=True)
        frames = self.rendered_frames - before
        self.sink.emit(ImageTaken(index + 1, image, ImageKind.RETAKE, frames))
        return image

    def render_window(self, camera: CameraId, window: Window, retake: bool = False) -> np.ndarray:
        """Only ``window`` of the camera's image: the full image's crop, (h, w, 3) uint8.

        ``retake``: a window of the instant just taken (same noise: after a window that
        missed, where a preview places the target), counted as a retake.
        """
        index, before = self.camera_index(camera), self.rendered_frames
        image = self._renderer.render_window(self.data, index, window, retake=retake)
        frames = self.rendered_frames - before
        kind = ImageKind.RETAKE if retake else ImageKind.WINDOW
        self.sink.emit(ImageTaken(index + 1, image, kind, frames, window))
        return image

    def render_preview(self, camera: CameraId, binning: int) -> np.ndarray:
        """The camera's whole view binned ``binning`` x ``binning`` (for finding where to
        look), (H/b, W/b, 3) uint8, counted as a render."""
        index, before = self.camera_index(camera), self.rendered_frames
        image = self._renderer.render_preview(self.data, index, binning)
        frames = self.rendered_frames - before
        self.sink.emit(ImageTaken(index + 1, image, ImageKind.PREVIEW, frames, binning=binning))
        return image

    @property
    def render_count(self) -> int:
        """Images this simulator drew so far, each one a render: full frames, windows,
        retakes and previews (:class:`~headsim.sim.events.RenderCounts` by kind)."""
        return self._renderer.render_count

    @property
    def rendered_frames(self) -> float:
        """Pixels rendered so far by this simulator, in full frames."""
        return self._renderer.rendered_frames


def for_settings(
    settings: HeadSettings,
    scene: str | Path = "default",
    settle_mode: str = "kinematic",
    sink: EventSink | None = None,
    room: RoomSpec | None = None,
) -> HeadSim:
    """The simulator for ``settings`` in ``scene`` (with ``room`` in it, if given): the one
    builder that code outside the simulator, the procedures, the runner and the tests
    goes through."""
    return HeadSim(scene, settings, settle_mode=settle_mode, sink=sink, room=room)


def start_views(
    settings: HeadSettings, scene: str = "default", eye_angles_rad: Sequence[float] = ()
) -> tuple[StereoView, ...]:
    """The view of the head ``settings`` at its start pose in ``scene``, then from each
    eye-encoder angle (rad): what a fresh simulator's :meth:`HeadSim.stereo_views` gives
    (e.g. for a calibration or an area layout)."""
    with HeadSim(scene, settings) as sim:
        return sim.stereo_views(eye_angles_rad)


def effective_initial_direction(
    settings: HeadSettings, index: int, goal_u: float | None = None
) -> float:
    """:meth:`HeadSim.effective_initial_direction` of camera ``index`` (0: Ca1, 1: Ca2), rad,
    from the head's settings alone."""
    cam = settings.cameras[index]
    u_c, v_c = cam.image_centre
    pixel = np.array([u_c if goal_u is None else goal_u, v_c])
    xy = cam.pinhole().normalise(pixel)  # raises if no ray
    eye_from_cv = eye_from_camera_rotation(
        names.EYE_CAMERAS[index].inward,
        cam.mount_yaw_rad,
        cam.mount_pitch_rad,
        cam.mount_roll_rad,
    )
    ray_eye = eye_from_cv @ np.array([xy[0], xy[1], 1.0])
    yaw = math.atan2(ray_eye[0], ray_eye[2])
    return yaw if index == 0 else -yaw
