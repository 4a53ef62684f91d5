"""Every MJCF name the Python code uses, in one place (models/*.xml), and the
:class:`Camera` type that ties each eye camera's number, name and inward sign together."""

from __future__ import annotations

from dataclasses import dataclass

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


@dataclass(frozen=True)
class Camera:
    """One eye camera: ``index`` into ``settings.cameras`` (0, 1), its MJCF ``name``, and
    ``inward``: the sign of a yaw that turns it inward, about H's +y (docs/equations.md:
    +1 for Ca1, whose inward direction is its +x; -1 for Ca2)."""

    index: int
    name: str
    inward: float

    @property
    def number(self) -> int:
        """The paper's camera number: 1 (Ca1) or 2 (Ca2)."""
        return self.index + 1

    @classmethod
    def of(cls, camera: int | str | Camera) -> Camera:
        """The camera given as 1 or 2 (the paper's Ca1, Ca2), its MJCF name, or itself."""
        if isinstance(camera, Camera):
            return camera
        if isinstance(camera, int) and not isinstance(camera, bool) and camera in (1, 2):
            return EYE_CAMERAS[camera - 1]
        if camera in CAMERAS:
            return EYE_CAMERAS[CAMERAS.index(str(camera))]
        raise ValueError(f"unknown camera {camera!r}; allowed: 1, 2, {', '.join(CAMERAS)}")


#: Ca1 and Ca2, in the order of ``settings.cameras``.
EYE_CAMERAS = (Camera(0, CAMERAS[0], 1.0), Camera(1, CAMERAS[1], -1.0))

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
#: Colour of each relative-positioning object (models/scene_blocks.xml).
RELATIVE_OBJECT_COLOURS = dict(
    zip(RELATIVE_OBJECTS, ("red", "green", "blue", "yellow", "magenta", "cyan"), strict=True)
)

# Scene files in models/, by short name.
SCENES = {
    "default": "scene.xml",
    "base": "scene_base.xml",
    "chessboard": "scene_chessboard.xml",
    "blocks": "scene_blocks.xml",
}
HEAD_MODEL = "head.xml"

# Geom group holding the head's own visual geoms; the eye cameras never draw it.
HEAD_VISUAL_GROUP = 3

# The textured room (headsim.sim.textured_scene): the base scene's table plane and key
# light, which the room replaces, and the room's own surfaces.
TABLE_PLANE = "floor"
KEY_LIGHT = "key_light"
ROOM_FLOOR = "room_floor"
ROOM_WALLS = ("room_wall_back", "room_wall_left", "room_wall_right")
ROOM_TABLE = "room_table"
#: Geom group of the room's surfaces and objects (drawn by the eye cameras).
ROOM_GROUP = 0
