"""Every MJCF name the Python code uses, in one place (headsim/models/*.xml)."""

from __future__ import annotations

# Bodies and frames.
NECK_BASE = "neck_base"
NECK_YAW_LINK = "neck_yaw_link"
NECK_PITCH_LINK = "neck_pitch_link"
HEAD = "head"  # the head frame H
EYE_BODIES = ("eye1", "eye2")

# Joints.
NECK_YAW = "neck_yaw"
NECK_PITCH = "neck_pitch"
EYE_JOINTS = ("eye1_yaw", "eye2_yaw")
EYE_MOTOR_JOINT = EYE_JOINTS[0]  # the motor shaft and its encoder sit on eye 1

# Cameras, indexed 0 -> Ca1 (left, x = -D/2 in H), 1 -> Ca2 (right).
CAMERAS = ("cam1", "cam2")

# Actuators.
NECK_YAW_MOTOR = "neck_yaw_motor"
NECK_PITCH_MOTOR = "neck_pitch_motor"
EYE_MOTOR = "eye_motor"

# Equality coupling the two eyes to the one motor.
EYE_COUPLING = "eye_coupling"

# Keyframes.
HOME = "home"

# Props in the scenes.
MARKERS = ("marker_red", "marker_green", "marker_blue")
CALIBRATION_BALL = "calibration_ball"  # yellow, 8 mm
MARKER_COLOURS = {"marker_red": "red", "marker_green": "green", "marker_blue": "blue"}
CHESSBOARD = "chessboard"
BLOCKS = "blocks"
RELATIVE_OBJECTS = tuple(f"object_{i}" for i in range(1, 7))
#: Colour of each relative-positioning object (headsim/models/scene_blocks.xml).
RELATIVE_OBJECT_COLOURS = dict(
    zip(RELATIVE_OBJECTS, ("red", "green", "blue", "yellow", "magenta", "cyan"), strict=True)
)

# Scene files in headsim/models/, by short name.
SCENES = {
    "default": "scene.xml",
    "base": "scene_base.xml",
    "chessboard": "scene_chessboard.xml",
    "blocks": "scene_blocks.xml",
}
HEAD_MODEL = "head.xml"

# Geom group holding the head's own visual geoms; the eye cameras never draw it.
HEAD_VISUAL_GROUP = 3
