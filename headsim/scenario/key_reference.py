"""Every scenario key the loader accepts, with its type, limits, default and meaning.

The type, what is allowed and the default come from the getters themselves
(:func:`headsim.scenario.tables.collecting_keys`), recorded while the real
loader reads every shipped scenario and :data:`VARIANTS` of them that reach the
branches no shipped file takes.  Only the meaning is written here, one line per
key (:data:`DESCRIPTIONS`); the documentation's scenario reference is made from
:func:`accepted_keys`, and a test fails when a key has no line or a line no key.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from headsim.scenario.loading import (
    read_toml,
    resolve_path,
    scenario_files,
    scenario_from_document,
    set_field,
)
from headsim.scenario.tables import KeyUse, collecting_keys
from headsim.sim import imperfections
from headsim.sim.model import MODELS_DIR


@dataclass(frozen=True)
class Key:
    """One accepted key: how the getter reads it, and what it means."""

    path: str
    kind: str
    allowed: str
    default: str
    description: str


Edit = Callable[[dict[str, Any]], dict[str, Any]]


def _without(doc: dict[str, Any], dotted: str) -> dict[str, Any]:
    """A copy of ``doc`` without the field at ``dotted``."""
    head, _, rest = dotted.partition(".")
    out = dict(doc)
    if not rest:
        out.pop(head, None)
    elif isinstance(out.get(head), dict):
        out[head] = _without(out[head], rest)
    return out


def _edits(*steps: tuple[str, Any]) -> Edit:
    """Set (or, with value None, drop) dotted fields in turn."""

    def edit(doc: dict[str, Any]) -> dict[str, Any]:
        for dotted, value in steps:
            doc = _without(doc, dotted) if value is None else set_field(doc, dotted, value)
        return doc

    return edit


_PATH = "scene.pursuit.path"
#: Shipped scenarios changed to take the readers' other branches: (scenario, edit).
VARIANTS: tuple[tuple[str, Edit], ...] = (
    (
        "quickstart",
        _edits(
            (
                "belief",
                {
                    "baseline_m": 0.15,
                    "neck_d1_m": 0.12,
                    "neck_a2_m": 0.09,
                    "side_offset_m": [0.0, 0.0],
                },
            ),
        ),
    ),
    ("chessboard", _edits(("belief", {}))),  # the paper's preset: other belief defaults
    (  # listed markerless targets: on an object, and a world point on a surface
        "natural_field",
        _edits(
            (
                "scene.room.targets",
                [
                    {"name": "poster_centre", "object": "poster", "point_object_m": [0, 0, 0]},
                    {"name": "poster_too", "point_world_m": [-0.35, 1.6, 0.1]},
                ],
            ),
        ),
    ),
    (
        "relative_positioning",
        _edits(("scene.objects", None), ("scene.random_objects", {"count": 3})),
    ),
    (
        "tracking",
        _edits(
            ("scene.moving_target.waypoints_head_m", None),
            ("scene.moving_target.waypoints_world_m", None),
            ("scene.moving_target.random", {"waypoints": 3}),
        ),
    ),
    (
        "pursuit",
        _edits(
            (
                _PATH,
                {
                    "kind": "sinusoid",
                    "centre_world_m": [0.0, 1.0, 0.21],
                    "amplitude_m": [0.1, 0.0, 0.05],
                    "frequency_hz": 0.5,
                    "phase_rad": [0.0, 0.0, 0.0],
                },
            ),
        ),
    ),
    (
        "pursuit",
        _edits(
            (
                _PATH,
                {
                    "kind": "random_walk",
                    "start_world_m": [0.0, 1.0, 0.21],
                    "max_speed_m_s": 0.3,
                    "box_half_m": [0.2, 0.2, 0.1],
                    "seed": 5,
                },
            ),
        ),
    ),
    (
        "pursuit",
        _edits(
            (
                _PATH,
                {"kind": "throw", "start_world_m": [0.0, 1.0, 0.21], "velocity_m_s": [0, 0, 1.5]},
            ),
            ("scene.pursuit.duration_s", 0.4),
        ),
    ),
    ("pursuit", _edits((_PATH, {"kind": "static", "point_world_m": [0.0, 1.0, 0.21]}))),
    (
        "pursuit",
        _edits(
            (
                _PATH,
                {
                    "kind": "jump",
                    "start_world_m": [0.0, 1.0, 0.21],
                    "end_world_m": [0.1, 1.0, 0.25],
                    "time_s": 0.1,
                },
            ),
        ),
    ),
    (  # a head as an MJCF file and its mapping: the shipped independent_eyes file's
        "quickstart",
        _edits(
            ("head.model", str(MODELS_DIR / "independent_eyes.xml")),
            (
                "head.mapping",
                {
                    "head_body": "head_frame",
                    "neck_yaw": "neck_yaw_joint",
                    "neck_pitch": "neck_pitch_joint",
                    "eyes": "independent",
                    "left_eye": "left_eye_pan",
                    "right_eye": "right_eye_pan",
                    "cameras": ["left_camera", "right_camera"],
                },
            ),
        ),
    ),
    (  # the same with version and vergence, a neck roll and an eye tilt: the icub file's
        "quickstart",
        _edits(
            ("head.model", str(MODELS_DIR / "icub.xml")),
            (
                "head.mapping",
                {
                    "head_body": "head_center",
                    "neck_yaw": "neck_yaw",
                    "neck_pitch": "neck_pitch",
                    "neck_roll": "neck_roll",
                    "eyes": "version_vergence",
                    "left_eye": "l_eye_pan",
                    "right_eye": "r_eye_pan",
                    "version": "eyes_version_motor",
                    "vergence": "eyes_vergence_motor",
                    "eye_tilt": "eyes_tilt",
                    "cameras": ["l_eye_camera", "r_eye_camera"],
                },
            ),
        ),
    ),
)


def collect_uses() -> dict[str, KeyUse]:
    """Every key the getters read over the shipped scenarios and :data:`VARIANTS`, by path."""
    uses: dict[str, KeyUse] = {}
    with collecting_keys() as seen:
        for path in scenario_files():
            doc = read_toml(path)
            scenario_from_document(doc, path.stem, directory=path.parent)
            _fold(uses, seen)
        for name, edit in VARIANTS:
            path = resolve_path(name)
            scenario_from_document(edit(read_toml(path)), name, directory=path.parent)
            _fold(uses, seen)
    return dict(sorted(uses.items()))


def _fold(uses: dict[str, KeyUse], seen: dict[str, KeyUse]) -> None:
    """Add this document's uses; a default or a range that differs between documents
    depends on other keys (the range is then shown as an example)."""
    for path, use in seen.items():
        old = uses.get(path)
        if old is None or not old.kind:
            uses[path] = use
        elif use.kind:
            default = old.default if use.default == old.default else "depends on other keys"
            allowed = old.allowed
            if use.allowed != old.allowed and not allowed.startswith("e.g. "):
                allowed = f"e.g. {allowed}"
            uses[path] = KeyUse(path, old.kind, allowed, default)
    seen.clear()


def accepted_keys() -> list[Key]:
    """Every accepted key with its meaning (KeyError-free: a key without a line gets "")."""
    return [
        Key(u.path, u.kind, u.allowed, u.default, DESCRIPTIONS.get(u.path) or _meaning(u.path))
        for u in collect_uses().values()
    ]


def _meaning(path: str) -> str:
    """A camera's imperfection setting's declared meaning (one registered after import)."""
    table, _, name = path.partition(".")
    return imperfections.meanings().get(name, "") if table in ("cam1", "cam2") else ""


_CAMERA = {
    "": "One camera's settings; a missing key comes from the camera's preset.",
    "preset": "The camera's preset (default: `head.preset`).",
    "width": "Image width, px.",
    "height": "Image height, px.",
    "kx": "Focal length along the image's u axis, px.",
    "ky": "Focal length along the image's v axis, px.",
    "cx": "Principal point's column, px (pixel centres at integer coordinates).",
    "cy": "Principal point's row, px.",
    **imperfections.meanings(),  # declared with each image imperfection
    "nodal_offset_m": "Optical centre in front of the eye's yaw axis, m (lenses: 0.01-0.03).",
    "side_offset_m": "Optical centre along the camera's x from the yaw axis, m (mounting: up to 0.002).",
    "eye_axis_tilt_rad": "The eye's yaw axis leaning forward, rad (machining: a few mrad).",
}
_RANDOM_BOX = {
    "depth_m": "Depth range z_h of the drawn points in H, m.",
    "lateral": "Largest |x_h / z_h| of a drawn point (half the horizontal field, as a ratio).",
    "vertical": "Largest |y_h / z_h| of a drawn point.",
}
_POSITION = {
    "position_head_m": "Position in H at the start pose (neck and eyes at 0), m; or `position_world_m`.",
    "position_world_m": "Position in W, m; or `position_head_m`.",
}
_PURSUIT = "scene.pursuit"

#: One line per key: what it means, with its unit.
DESCRIPTIONS: dict[str, str] = {
    "description": "One line saying what the experiment is; `headsim list` shows it. Required.",
    "seed": "Seed of the image noise and of every random layout; `--seed` replaces it.",
    "fast": "Fields merged over the file by `--fast`: tables key by key, other values replaced.",
    "head": "The head's geometry and joints; missing keys come from `head.preset`.",
    "head.model": "Which head: a shipped one (paper, independent_eyes, icub) or a path to your head's MJCF file.",
    "head.mapping": "With an MJCF `head.model`: the names of its joints, body H and cameras.",
    "head.mapping.head_body": "The body whose frame is H at all joints zero (midway between the optical centres, x right, y down, z forward).",
    "head.mapping.neck_yaw": "The neck's yaw joint: about W's +z at the base, or above a pitch at the base (the iCub's); leave out on a head without one (Model 2 only).",
    "head.mapping.neck_pitch": "The neck's pitch joint, about W's +x (above the yaw, or at the base through W's origin), positive looking up.",
    "head.mapping.neck_roll": "The neck's roll joint, held at zero (leave out on a head without one).",
    "head.mapping.eyes": "How the eyes are driven: one motor on `left_eye` with `right_eye` following (coupled), a motor each (independent), or version and vergence actuators (version_vergence).",
    "head.mapping.version": 'With `eyes = "version_vergence"`: the actuator of length (left - right) / 2.',
    "head.mapping.vergence": 'With `eyes = "version_vergence"`: the actuator of length left + right.',
    "head.mapping.eye_tilt": "The eyes' common tilt joint, held at zero (leave out on a head without one).",
    "head.mapping.left_eye": "The pan joint of the eye carrying Ca1 (at -x in H), positive inward.",
    "head.mapping.right_eye": "The pan joint of the eye carrying Ca2 (at +x in H), positive inward.",
    "head.mapping.cameras": "The two eye cameras, [Ca1, Ca2]: left, then right.",
    "head.preset": "Defaults for the head and both cameras: the ideal head, the paper's, or a realistic one.",
    "head.baseline_m": "True distance between the eyes' yaw axes (the optical centres, on them), m. Without `[belief]` the ideal and paper presets believe it too (`belief.sources`: `truth`).",
    "head.neck_d1_m": "Height of the neck's pitch axis above its yaw base (D-H d1 of eq. 1), m; believed as `head.baseline_m` is.",
    "head.neck_a2_m": "Height of H above the pitch axis (D-H a2 of eq. 1), m; believed as `head.baseline_m` is.",
    "head.encoder_resolution_rad": "One encoder count of every joint, rad.",
    "head.initial_direction_rad": "Each eye's effective initial direction alpha_ei, rad (or `mount_yaw_rad`, not both).",
    "head.mount_yaw_rad": "Each eye's raw mount yaw, rad (or `initial_direction_rad`, not both).",
    "head.mount_pitch_rad": "Each eye's mount pitch, rad.",
    "head.mount_roll_rad": "Each eye's mount roll, rad.",
    "head.settle": "How joints reach a commanded angle: set kinematically, or driven by MuJoCo's physics.",
    "head.backlash_rad": "Backlash: every joint settles half of it short, on the side it came from, rad.",
    "head.count_error": "If true, the true angle lies anywhere within the encoder count read (seeded).",
    "head.render_offsamples": "MuJoCo multisampling per pixel (Mesa caps it at 4).",
    "head.render_supersample": "Render this many times larger and area-average down (1: faster, coarser).",
    **{f"cam{i}" + (f".{k}" if k else ""): v for i in (1, 2) for k, v in _CAMERA.items()},
    "belief": "What the head believes of itself; estimators use only this. Without it: the realistic preset's design, else the `[head]` values (results.json's `belief.sources` says which).",
    "belief.baseline_m": "Believed baseline, m (default: the preset's belief, else the design's).",
    "belief.neck_d1_m": "Believed neck d1, m (default as `belief.baseline_m`).",
    "belief.neck_a2_m": "Believed neck a2, m (default as `belief.baseline_m`).",
    "belief.side_offset_m": "Believed line-of-sight (side) offset per camera, m, until calibrated.",
    "experiment": "What is measured and how.",
    "experiment.procedure": "The procedure that runs (one module each in `headsim.procedures`). Required.",
    "experiment.interpolate": "Sub-step fixation angles, interpolated between the last two encoder steps.",
    "experiment.midline_px": "Model 2's near-midline remedy: an image whose target is nearer the goal column than this is taken again, px.",
    "experiment.remedy_px": "Model 2's near-midline remedy: the eye angle of that image, as image motion away, px.",
    "experiment.goal_columns_px": "The servo's goal column per camera, px, as the user tells the head (default: the image centres).",
    "experiment.calibration": "Sec. V before the experiment, in the default scene (required by `calibration`).",
    "experiment.calibration.from": "A `head.json` from `headsim calibrate` to use instead, relative to the scenario file.",
    "experiment.calibration.targets": "Number of calibration-ball positions.",
    "experiment.calibration.depth_m": "Depth range z_h of the ball positions in H, m.",
    "experiment.calibration.lateral": "Largest |x_h / z_h| of a ball position.",
    "experiment.calibration.vertical": "Largest |y_h / z_h| of a ball position.",
    "experiment.calibration.depth_noise_m": "Error of the tape-measured depth of each ball, m.",
    "experiment.calibration.position_noise_m": "Error of every measured coordinate of every ball, m.",
    "experiment.calibration.extended": "Also fit each camera's v0, kx/ky and line-of-sight offset (beyond the paper).",
    "experiment.calibration.lines_of_sight": "With `extended`: also fit each eye's line-of-sight offset.",
    "experiment.calibration.layout": "Depths uniform in `depth_m`, or most balls at the near end and the rest far.",
    "experiment.calibration.positions_world_m": "The ball positions [[x, y, z], ...] in W, m, given instead of drawn (`targets` is their number).",
    "experiment.calibration.near_fraction": "`near_far` only: share of balls at the near end (default b / (a + b)).",
    "experiment.stereo": "The calibrated stereo baseline (procedure `stereo`): Zhang's calibration from chessboard views, then each target triangulated at eye angle 0.",
    "experiment.stereo.views": "Chessboard poses rendered for the calibration (at least 5 must show the whole board).",
    "experiment.stereo.distance_m": "The board centre's distance from camera 1, [low, high], m.",
    "experiment.stereo.max_tilt_rad": "The board's largest tilt about its x and y axes, rad.",
    "experiment.stereo.refine_intrinsics": "stereoCalibrate refines each camera's K, k1, k2 (false: keeps each camera's own calibration).",
    "experiment.stereo.board_seed": "The board poses' seed (default: the scenario's seed), so that a study can calibrate with the poses it drew before.",
    "experiment.stereo.board_look": "How each camera finds the board: `full_frame`, or `windowed` (a binned preview, then a window on the board: the same corners).",
    "experiment.stereo.from": "A stored stereo calibration file (`headsim.stereo.calibration_file`) to triangulate with instead of calibrating (no board keys then).",
    "experiment.stereo.look": "With `from`: each camera's look for a target, the full frame or `once` (a binned preview, then a window where it shows the target).",
    "experiment.stereo.pattern": "The board's inner corners, [columns, rows]: the chessboard scene's board, [8, 6].",
    "experiment.zoom_fixed_points": "Each camera's principal point as the fixed point of a zoom (procedure `zoom_fixed_points`): chessboard images at the head's focal lengths and at `zoom` times them; only pixels enter the fit.",
    "experiment.zoom_fixed_points.zoom": "The focal length ratio of the second images.",
    "experiment.zoom_fixed_points.poses": "Chessboard poses rendered at both focal lengths.",
    "experiment.zoom_fixed_points.board_seed": "The seed of the board poses' draws (absent: the scenario's seed).",
    "experiment.servo": "The eye and neck servo (`headsim.active.servo_types.ServoConfig`).",
    "experiment.servo.windows": "Render only a window around where the target is expected (false: every image a full frame; same answers, more pixels).",
    "experiment.servo.tolerance_px": "Stop when the target's column is this close to the goal (or within half an encoder step's motion), px.",
    "experiment.servo.max_iterations": "Servo steps before the fixation gives up.",
    "experiment.servo.probe_steps": "Encoder steps of the first probe when no gain is known (grown x4 until the image moves `min_probe_px`).",
    "experiment.servo.min_probe_px": "Image motion a probe must cause before the gain is measured, px.",
    "experiment.servo.min_secant_steps": "Moves shorter than this, in encoder steps, do not update the gain.",
    "experiment.servo.average_fixation": "Average each fixation over images spread across one pixel (about twice the renders).",
    "scene": "What the procedure measures and where it is.",
    "scene.targets": "Fixed targets (model2, model1; for calibration: optional check targets).",
    "scene.targets[].name": "The target's name, unique (default `target_N`).",
    "scene.targets[].body": "The marker body that stands for the target.",
    **{f"scene.targets[].{k}": v for k, v in _POSITION.items()},
    "scene.random_targets": "More targets drawn from the seed, named `random_N`.",
    "scene.random_targets.count": "Number of random targets.",
    "scene.random_targets.body": "The marker body of every random target.",
    **{f"scene.random_targets.{k}": v for k, v in _RANDOM_BOX.items()},
    "scene.random_targets.within": "`box` refuses a drawn point out of reach and draws again one the scene hides; `reach` draws any refused point again (each redraw counted).",
    "scene.chessboard": "The chessboard (procedure `chessboard`); it faces the head.",
    "scene.chessboard.corners": 'Which inner corners are measured: `"all"` or an array of corner indices, row-major from the top-left.',
    **{
        f"scene.chessboard.{k}": "Top-left inner corner: " + v[0].lower() + v[1:]
        for k, v in _POSITION.items()
    },
    "scene.blocks": "The blocks' cross point (procedure `relative_positioning`).",
    **{f"scene.blocks.{k}": "Cross point: " + v[0].lower() + v[1:] for k, v in _POSITION.items()},
    "scene.objects": "Objects measured relative to the cross point, each seen by both cameras at the start pose or in all four images at the cross point's fixations; those not listed are parked out of view.",
    "scene.objects[].body": "The object body (`object_1`..`object_6`).",
    **{f"scene.objects[].{k}": v for k, v in _POSITION.items()},
    "scene.random_objects": "Objects at random positions instead of `[[scene.objects]]`, drawn from the seed.",
    "scene.random_objects.count": "Number of objects placed.",
    **{f"scene.random_objects.{k}": v for k, v in _RANDOM_BOX.items()},
    "scene.moving_target": "The marker moved along waypoints (procedure `tracking`).",
    "scene.moving_target.name": "The moving target's name.",
    "scene.moving_target.body": "The marker body that moves.",
    "scene.moving_target.duration_s": "Time to pass all waypoints, s.",
    "scene.moving_target.steps": "Fixations, at equal intervals from t = 0. Required.",
    "scene.moving_target.waypoints_head_m": "Waypoints [[x, y, z], ...] in H at the start pose, at least 2, passed at equal times, m.",
    "scene.moving_target.waypoints_world_m": "Waypoints [[x, y, z], ...] in W, at least 2, m.",
    "scene.moving_target.random": "Random waypoints drawn from the seed instead.",
    "scene.moving_target.random.waypoints": "Number of random waypoints.",
    **{f"scene.moving_target.random.{k}": v for k, v in _RANDOM_BOX.items()},
    "scene.room": "A textured room around the head (every procedure): floor, walls and table with generated textures, objects, clutter from the seed, and the light.",
    "scene.room.surface": "Texture class of the floor, walls and table: `pink` (1/f noise), `grating`, `low` (faint gradient), `repetitive` (stripes).",
    "scene.room.table_top_z_m": "Height of the table top in W's z, m (the eyes are about 0.2 m up; default -0.35); the clutter rests on it.",
    "scene.room.clutter": "Objects drawn from the seed (box, cylinder or sphere, 3-8 cm half-size, a texture class each), resting on the table.",
    "scene.room.clutter_depth_m": "Range of W's y (depth in front of the head) of the clutter's centres, m.",
    "scene.room.targets": "Markerless targets (`model2`, `model1`; told by a click in camera 1's image): a count drawn from the seed where the start pose shows both cameras (0: none), or a list.",
    "scene.room.targets[].name": "The listed target's name, unique (`surface_` is reserved for drawn ones). Listed targets are measured in file order.",
    "scene.room.targets[].object": "The room object the point lies on (an objects entry, `clutter_N`, `room_floor`, `room_table`, `room_wall_*`).",
    "scene.room.targets[].point_object_m": "The point in the object's frame, m; must lie within 1 mm of its surface.",
    "scene.room.targets[].point_world_m": "Without `object`: the point in W, m; must lie within 1 mm of a surface of the room.",
    "scene.room.targets_depth_m": "Depth range in H of the markerless targets, m (a draw outside is drawn again, counted).",
    "scene.room.targets_lateral": "Largest |x_h / z_h| of a markerless target's draw direction (0.25: the shared field).",
    "scene.room.targets_vertical": "Largest |y_h / z_h| of a markerless target's draw direction.",
    "scene.room.click_error_px": "Standard deviation of the click that tells the head a markerless target, px per axis.",
    "scene.room.targets_as": "`surface`: each target by correlation; `markers`: an emissive marker put 5 mm out along the surface's normal, found by its colour (the marker twin).",
    "scene.room.band_px": "Half-height of the band along camera 1's row in which camera 2 searches the clicked point, px (the head knows no focal length).",
    "scene.room.light": "The key light and the ambient level.",
    "scene.room.light.direction_world": "Direction the key light shines along, in W (normalised).",
    "scene.room.light.diffuse": "Key light's diffuse intensity, 0-1.",
    "scene.room.light.ambient": "Ambient light everywhere, 0-1.",
    "scene.room.light.shadows": "Whether the key light casts shadows (a shadow map: dearer renders).",
    "scene.room.objects": "Textured objects placed in the room.",
    "scene.room.objects[].name": "The object's name, unique (default `item_N`; `clutter_`, `room_` and the scenes' bodies are reserved).",
    "scene.room.objects[].shape": "`box`, `cylinder`, `sphere`, `plane` or `mesh` (its `vertices_m` and `faces`, no `size_m`).",
    "scene.room.objects[].size_m": "MuJoCo's sizes, m: a box's half-lengths, a cylinder's radius and half-height (then 0), a sphere's radius (then 0, 0), a plane's half-sides (then 0).",
    "scene.room.objects[].pos_world_m": "The object's centre in W, m.",
    "scene.room.objects[].yaw_rad": "Rotation about W's z, rad.",
    "scene.room.objects[].pitch_rad": "Then about the object's own x, rad (a plane at pi/2 stands up facing the head).",
    "scene.room.objects[].texture": "Texture class: `pink`, `grating`, `low` or `repetitive`.",
    "scene.room.objects[].texture_seed": "Seed of the object's texture; default from the scenario's seed.",
    "scene.room.objects[].period_px": "`grating` and `repetitive`: the period in texture pixels (256 to a tile).",
    "scene.room.objects[].orientation_rad": "`grating` and `repetitive`: direction the pattern varies along, rad from the texture's columns.",
    "scene.room.objects[].checks": "`repetitive`: checks instead of stripes.",
    "scene.room.objects[].vertices_m": "`mesh`: its vertices [[x, y, z], ...] in the object's frame (4-1000, within 2 m of its origin), m.",
    "scene.room.objects[].faces": "`mesh`: its triangles [[i, j, k], ...] of vertex indices, counter-clockwise seen from outside (each textured by projecting it onto the object-frame plane it faces most).",
    "scene.room.objects[].tile_m": "`plane` and `mesh`: the side of one texture tile on the surface, m.",
    _PURSUIT: "The live head pursuing a moving marker (procedure `pursuit`).",
    f"{_PURSUIT}.name": "The pursued target's name.",
    f"{_PURSUIT}.body": "What moves: a marker body, or a `[[scene.room.objects]]` name (clicked once, then tracked without markers).",
    f"{_PURSUIT}.duration_s": "Length of the pursuit, s.",
    f"{_PURSUIT}.click_error_px": "A room object's pursuit: the user's click in camera 1's first image, error per axis, px.",
    f"{_PURSUIT}.band_px": "A room object's pursuit: half-height of the band along camera 1's row in which camera 2 searches, px.",
    f"{_PURSUIT}.path": "How the target moves.",
    f"{_PURSUIT}.path.kind": "The kind of path; each kind takes its own keys below.",
    f"{_PURSUIT}.path.points_world_m": "`waypoints`: the points [[x, y, z], ...] in W, m.",
    f"{_PURSUIT}.path.speeds_m_s": "`waypoints`: the speed along each leg, m/s.",
    f"{_PURSUIT}.path.centre_world_m": "`sinusoid`: the centre in W, m.",
    f"{_PURSUIT}.path.amplitude_m": "`sinusoid`: the amplitude along x, y, z of W, m.",
    f"{_PURSUIT}.path.frequency_hz": "`sinusoid`: the frequency, Hz.",
    f"{_PURSUIT}.path.phase_rad": "`sinusoid`: the phase along x, y, z, rad.",
    f"{_PURSUIT}.path.start_world_m": "`random_walk`, `throw`, `jump`: the start in W, m.",
    f"{_PURSUIT}.path.max_speed_m_s": "`random_walk`: the largest speed, m/s.",
    f"{_PURSUIT}.path.box_half_m": "`random_walk`: half the box it stays in, along x, y, z, m.",
    f"{_PURSUIT}.path.seed": "`random_walk`: the walk's seed; default the scenario's `seed`.",
    f"{_PURSUIT}.path.end_world_m": "`jump`: where the target is from `time_s` on, in W, m.",
    f"{_PURSUIT}.path.time_s": "`jump`: when the target jumps from the start to the end, s.",
    f"{_PURSUIT}.path.velocity_m_s": "`throw`: the initial velocity in W, m/s (then gravity).",
    f"{_PURSUIT}.path.point_world_m": "`static`: the point in W, m.",
    f"{_PURSUIT}.path.windows_s": "When the target is visible: [[appear_s, disappear_s], ...]; default always.",
    f"{_PURSUIT}.live": "The live head's camera and motors.",
    f"{_PURSUIT}.live.frame_rate_hz": "Camera frame rate, Hz.",
    f"{_PURSUIT}.live.exposure_s": "Exposure time, s (> 0 with `blur_subframes` > 1: motion blur).",
    f"{_PURSUIT}.live.blur_subframes": "Renders averaged per frame for motion blur.",
    f"{_PURSUIT}.live.latency_frames": "Frames between an image and the command it causes.",
    f"{_PURSUIT}.live.eye_max_speed": "Eye motor's speed limit, rad/s.",
    f"{_PURSUIT}.live.eye_max_accel": "Eye motor's acceleration limit, rad/s^2.",
    f"{_PURSUIT}.live.neck_max_speed": "Neck motors' speed limit, rad/s.",
    f"{_PURSUIT}.live.neck_max_accel": "Neck motors' acceleration limit, rad/s^2.",
    f"{_PURSUIT}.gaze": "The gaze behaviour.",
    f"{_PURSUIT}.gaze.mode": "Model 1 with the neck, or the eyes alone.",
    f"{_PURSUIT}.gaze.predictor": "A constant-velocity predictor against the latency.",
    f"{_PURSUIT}.gaze.saccade": "Saccade profile: minimum jerk or bang-bang.",
    f"{_PURSUIT}.gaze.saccade_threshold_rad": "A fixation correction larger than this starts a saccade, rad.",
    f"{_PURSUIT}.gaze.fixation_tolerance_px": "Image error within which the target counts as fixated, px.",
}
