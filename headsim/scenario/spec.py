"""The checked scenario: its frozen dataclasses and the constants of the schema.

What :func:`headsim.scenario.loading.load_scenario` returns: a :class:`Scenario`
(the head's settings, the scene's :class:`SceneSpec`, the experiment's
:class:`ExperimentSpec`), random parts already drawn from its seed.  Positions
in metres (world frame W unless named otherwise), angles in radians, pixels as
OpenCV's.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, is_dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from headsim import paper
from headsim.procedures import contract as registry
from headsim.scenario.calibration_design import LAYOUTS
from headsim.sim import names
from headsim.sim.declared import Array, Choice, Flag, Setting, Text
from headsim.sim.settings import MAX_IMAGE_SIDE, HeadSettings, belief_sources
from headsim.sim.textured_scene import RoomSpec

if TYPE_CHECKING:
    from headsim.active.calibration_file import StoredCalibration
    from headsim.scenario.pursuit import PursuitSpec

#: Bodies of the default scene that can be measured, and the colour each is found by.
MARKER_BODIES = {**names.MARKER_COLOURS, names.CALIBRATION_BALL: "yellow"}


#: The chessboard of ``models/scene_chessboard.xml``: inner corners (columns, rows), square, m.
CHESSBOARD_PATTERN = (8, 6)


CHESSBOARD_SQUARE_M = paper.CHESSBOARD_SQUARE_M


#: Nearest a target may be to the head, m (z_h at the start pose).
MIN_DEPTH_M = 0.1


#: Farthest a target may be, m: beyond it one encoder step is centimetres of depth.
MAX_DEPTH_M = 10.0


#: The calibration's keys (``[experiment.calibration]``), each declared once; the ball
#: positions, given as an array of points, are read by the schema alone.
CALIBRATION_SOURCE = Text(
    "from",
    None,
    "A `head.json` from `headsim calibrate` to use instead, relative to the scenario file.",
    max_length=1000,
)
CALIBRATION_TARGETS = Setting(
    "targets", 60, 3, 1000, "", "Number of calibration-ball positions.", integer=True
)
_CALIBRATION_DEPTH_M = (0.25, 0.6)
CALIBRATION_DEPTH = Setting(
    "depth_m",
    _CALIBRATION_DEPTH_M,
    MIN_DEPTH_M,
    MAX_DEPTH_M,
    "m",
    "Depth range z_h of the ball positions in H, m.",
    count=2,
)
CALIBRATION_LATERAL = Setting(
    "lateral",
    0.16,
    0.0,
    1.0,
    "(|x_h / z_h|)",
    "Largest |x_h / z_h| of a ball position.",
    lo_open=True,
)
CALIBRATION_VERTICAL = Setting(
    "vertical", 0.08, 0.0, 1.0, "(|y_h / z_h|)", "Largest |y_h / z_h| of a ball position."
)
CALIBRATION_DEPTH_NOISE = Setting(
    "depth_noise_m", 0.0, 0.0, 0.1, "m", "Error of the tape-measured depth of each ball, m."
)
CALIBRATION_EXTENDED = Flag(
    "extended",
    True,
    "Also fit each camera's v0, kx/ky and line-of-sight offset (beyond the paper).",
)
CALIBRATION_POSITION_NOISE = Setting(
    "position_noise_m",
    0.0,
    0.0,
    0.1,
    "m",
    "Error of every measured coordinate of every ball, m.",
)
CALIBRATION_LINES_OF_SIGHT = Flag(
    "lines_of_sight", False, "With `extended`: also fit each eye's line-of-sight offset."
)
CALIBRATION_LAYOUT = Choice(
    "layout",
    LAYOUTS,
    "uniform",
    "Depths uniform in `depth_m`, or most balls at the near end and the rest far.",
)
CALIBRATION_NEAR_FRACTION = Setting(
    "near_fraction",
    None,
    0.0,
    1.0,
    "(share of balls)",
    "`near_far` only: share of balls at the near end (default b / (a + b)).",
    lo_open=True,
    hi_open=True,
    optional=True,
)
#: The calibration's declared keys, in the order ``[experiment.calibration]`` reads them.
#: Read by its own reader, before the settings (their ``targets`` defaults to its length).
CALIBRATION_POSITIONS = Array(
    "positions_world_m",
    "an array of 3 to 1000 [x, y, z] positions in W, m",
    "The ball positions [[x, y, z], ...] in W, m, given instead of drawn (`targets` is their "
    "number).",
)
CALIBRATION_SETTINGS = (
    CALIBRATION_TARGETS,
    CALIBRATION_DEPTH,
    CALIBRATION_LATERAL,
    CALIBRATION_VERTICAL,
    CALIBRATION_DEPTH_NOISE,
    CALIBRATION_EXTENDED,
    CALIBRATION_POSITION_NOISE,
    CALIBRATION_LINES_OF_SIGHT,
    CALIBRATION_SOURCE,
    CALIBRATION_LAYOUT,
    CALIBRATION_NEAR_FRACTION,
)

#: The servo's keys (``[experiment.servo]``), each declared once.
SERVO_SETTINGS = (
    Setting(
        "tolerance_px",
        0.1,
        0.0,
        10.0,
        "px",
        "Stop when the target's column is this close to the goal (or within half an encoder "
        "step's motion), px.",
        lo_open=True,
    ),
    Setting(
        "max_iterations",
        25,
        1,
        1000,
        "",
        "Servo steps before the fixation gives up.",
        integer=True,
    ),
    Setting(
        "probe_steps",
        16,
        1,
        10000,
        "",
        "Encoder steps of the first probe when no gain is known (grown x4 until the image "
        "moves `min_probe_px`).",
        integer=True,
    ),
    Setting(
        "min_probe_px",
        2.0,
        0.0,
        100.0,
        "px",
        "Image motion a probe must cause before the gain is measured, px.",
        lo_open=True,
    ),
    Setting(
        "min_secant_steps",
        8,
        1,
        1000,
        "",
        "Moves shorter than this, in encoder steps, do not update the gain.",
        integer=True,
    ),
    Flag(
        "average_fixation",
        False,
        "Average each fixation over images spread across one pixel (about twice the renders).",
    ),
    Flag(
        "windows",
        True,
        "Render only a window around where the target is expected (false: every image a full "
        "frame; same answers, more pixels).",
    ),
)

#: ``[experiment]``'s keys that every procedure may read (a procedure's own are its
#: ``Procedure.keys``); ``procedure`` names one of the registered procedures.
PROCEDURE = Choice(
    "procedure",
    (),
    None,
    "The procedure that runs (one module each in `headsim.procedures`). Required.",
    required=True,
)
INTERPOLATE = Flag(
    "interpolate",
    True,
    "Sub-step fixation angles, interpolated between the last two encoder steps.",
)
MIDLINE = Setting(
    "midline_px",
    25.0,
    0.0,
    1000.0,
    "px",
    "Model 2's near-midline remedy: an image whose target is nearer the goal column than "
    "this is taken again, px.",
)
REMEDY = Setting(
    "remedy_px",
    120.0,
    0.0,
    1000.0,
    "px",
    "Model 2's near-midline remedy: the eye angle of that image, as image motion away, px.",
    lo_open=True,
)
GOAL_COLUMNS = Setting(
    "goal_columns_px",
    None,
    0.0,
    MAX_IMAGE_SIDE - 1.0,
    "px",
    "The servo's goal column per camera, px, as the user tells the head (default: the "
    "image centres).",
    count=2,
    optional=True,
)


#: Independent random streams drawn from the scenario seed.
STREAM_CALIBRATION, STREAM_TARGETS, STREAM_OBJECTS, STREAM_MOVING, STREAM_DEPTH_NOISE = range(1, 6)
#: The seed's streams of the room's surface targets and of their clicks (after the room's 6).
STREAM_SURFACE_TARGETS, STREAM_CLICKS = 7, 8


@dataclass(frozen=True)
class Placement:
    """A body put at a world position, m; ``source`` is the field it came from."""

    name: str
    body: str
    position_world_m: tuple[float, float, float]
    source: str


@dataclass(frozen=True)
class CalibrationSpec:
    """Sec. V calibration of the initial directions, before the experiment (default scene).

    ``targets`` ball positions drawn by ``procedures.calibration_layout``:
    depth z_h in ``depth_m``, |x_h/z_h| <= ``lateral``, |y_h/z_h| <= ``vertical``.
    ``depth_noise_m``: error of the tape-measured depth.  ``extended``: also
    fit each camera's vertical reference row and kx/ky, initial directions and
    line-of-sight offsets (beyond the paper).  ``position_noise_m``: error of
    every measured coordinate of each target (x_h, y_h, z_h), m; the depth
    noise adds to it on z_h.  ``lines_of_sight``: with ``extended``, also fit
    each eye's line-of-sight offset (default: on for the realistic preset).
    ``layout``: "uniform" (depths uniform in ``depth_m``) or "near_far" (a
    share ``near_fraction`` of the balls at the near end of ``depth_m`` and the
    rest at the far end; default b / (a + b), the design that pins each eye's
    line-of-sight offset best, see :mod:`headsim.scenario.calibration_design`).
    ``source``: a calibration file (``headsim calibrate``) to use instead of
    calibrating (a relative path is relative to the scenario file's
    directory); the other fields are then not used.  ``positions_world_m``: the
    ball positions in W, m, given instead of drawn (``targets`` is their number;
    ``depth_m``, ``lateral``, ``vertical`` and ``layout`` are then not used).
    """

    targets: int = int(CALIBRATION_TARGETS.fixed_default)
    depth_m: tuple[float, float] = _CALIBRATION_DEPTH_M
    lateral: float = CALIBRATION_LATERAL.fixed_default
    vertical: float = CALIBRATION_VERTICAL.fixed_default
    depth_noise_m: float = CALIBRATION_DEPTH_NOISE.fixed_default
    extended: bool = CALIBRATION_EXTENDED.default
    position_noise_m: float = CALIBRATION_POSITION_NOISE.fixed_default
    lines_of_sight: bool = CALIBRATION_LINES_OF_SIGHT.default
    source: str | None = None
    layout: str = "uniform"
    near_fraction: float | None = None
    positions_world_m: tuple[tuple[float, float, float], ...] | None = None


_SERVO: dict[str, Any] = {s.name: s.default for s in SERVO_SETTINGS}


@dataclass(frozen=True)
class ServoSpec:
    """The servo's bounds and tolerances (``headsim.active.servo_types.ServoConfig``).

    ``windows``: render only a window around where the target is expected (false:
    every image a full frame; the same answers, more pixels).  It changes no answer,
    so results.json records it only when set (:data:`UNANSWERED_SERVO_KEYS`).
    """

    tolerance_px: float = _SERVO["tolerance_px"]
    max_iterations: int = _SERVO["max_iterations"]
    probe_steps: int = _SERVO["probe_steps"]
    min_probe_px: float = _SERVO["min_probe_px"]
    min_secant_steps: int = _SERVO["min_secant_steps"]
    average_fixation: bool = _SERVO["average_fixation"]
    windows: bool = _SERVO["windows"]


#: Servo keys that change only the renders, never an answer: results.json records
#: each only where it differs from its default.
UNANSWERED_SERVO_KEYS = ("windows",)


def servo_record(servo: ServoSpec) -> dict[str, Any]:
    """The servo's keys as results.json records them (see :data:`UNANSWERED_SERVO_KEYS`)."""
    default = ServoSpec()
    return {
        key: value
        for key, value in asdict(servo).items()
        if key not in UNANSWERED_SERVO_KEYS or value != getattr(default, key)
    }


@dataclass(frozen=True)
class ExperimentSpec:
    """Which procedure, the calibration before it, and its options."""

    procedure: str
    calibration: CalibrationSpec | None
    interpolate: bool = INTERPOLATE.default
    midline_px: float = MIDLINE.fixed_default
    remedy_px: float = REMEDY.fixed_default
    servo: ServoSpec = field(default_factory=ServoSpec)
    #: The servo's goal column (u10, u20) of Ca1, Ca2, px, as the user tells the head
    #: (e.g. the principal point's, found with ``headsim.active.principal``); None: image centres.
    goal_columns_px: tuple[float, float] | None = None
    #: The procedure's own ``[experiment.<procedure>]`` table, as its ``options`` reader
    #: typed it (a dataclass; None: it has none, and results.json records no ``block``).
    block: Any = None


#: Field metadata of a procedure's block: results.json records the field only when it is
#: not its default (keys that studies give, so shipped scenarios' results stay as they are).
WHEN_GIVEN = "recorded_when_given"


def experiment_record(experiment: ExperimentSpec) -> dict[str, Any]:
    """The ``[experiment]`` spec as results.json records it (see :func:`servo_record`)."""
    record = {**asdict(experiment), "servo": servo_record(experiment.servo)}
    if experiment.block is None:
        del record["block"]
    elif is_dataclass(experiment.block):
        for f in fields(experiment.block):
            if f.metadata.get(WHEN_GIVEN) and getattr(experiment.block, f.name) == f.default:
                del record["block"][f.name]
    calibration = record["calibration"]
    if calibration is not None and calibration["positions_world_m"] is None:
        del calibration["positions_world_m"]  # recorded only when given
    return record


@dataclass(frozen=True)
class MovingTarget:
    """A body moved through ``waypoints_world_m`` (piecewise linear, equal times) over
    ``duration_s``, fixated ``steps`` times at equal intervals from t = 0."""

    name: str
    body: str
    waypoints_world_m: tuple[tuple[float, float, float], ...]
    duration_s: float
    steps: int

    @property
    def times_s(self) -> np.ndarray:
        return np.linspace(0.0, self.duration_s, self.steps) if self.steps > 1 else np.zeros(1)

    def position(self, t: float) -> np.ndarray:
        """World position at time ``t``, s, m."""
        points = np.asarray(self.waypoints_world_m)
        knots = np.linspace(0.0, self.duration_s, len(points))
        return np.array([np.interp(t, knots, points[:, k]) for k in range(3)])


#: Why the reach check refuses a point (:class:`headsim.scenario.reach.Refusal`'s ``code``):
#: behind, too near or too far; an eye angle, or a neck angle, beyond its range; inside
#: the eyes' offset from the neck's pitch axis; outside the view of every pose that can
#: fixate it; hidden from a camera by the scene; not in both views at the start pose
#: (only where a procedure starts there: a moving target's first position, a
#: chessboard corner, the blocks' cross point).
REFUSAL_REASONS = (
    "depth",
    "eye_range",
    "neck_range",
    "neck_offset",
    "not_in_any_view",
    "occluded",
    "start_view",
)


@dataclass(frozen=True)
class TargetAcceptance:
    """How the scene's targets came to be measured: listed, drawn, refused, accepted.

    ``within``: ``[scene.random_targets] within`` ("box" or "reach"; None: no
    random targets).  ``listed``: the ``[[scene.targets]]`` entries (each passed
    the reach check, else the file was refused).  ``drawn``: random draws made,
    the refused ones included; ``refused``: how many of them the reach check
    refused, by reason (:data:`REFUSAL_REASONS`), most common first: each was
    drawn again.  ``accepted``: the targets measured, listed and drawn.
    ``outside_start_view``: the names of the accepted targets that the start
    pose (neck and eyes at 0) does not show whole to both cameras, the edge of
    the field: the procedure finds them by a scan (the reach check before
    refused them).
    """

    within: str | None
    listed: int
    drawn: int
    refused: dict[str, int]
    accepted: int
    outside_start_view: tuple[str, ...]

    @property
    def refused_total(self) -> int:
        return sum(self.refused.values())

    @property
    def offered(self) -> int:
        """Targets listed or drawn: what "measured / drawn" divides by."""
        return self.listed + self.drawn


@dataclass(frozen=True)
class ListedSurfaceTarget:
    """``[[scene.room.targets]]``: a named point on the room's surfaces, on ``body`` at
    ``point_m`` in its frame, or (``body`` None) at the world point ``point_m``, m; checked
    to lie on the surface when read."""

    name: str
    body: str | None
    point_m: tuple[float, float, float]


#: How a room's markerless targets are measured (``[scene.room] targets_as``): as points of
#: the surfaces (by correlation), or each by an emissive marker put there (the twin).
TARGETS_AS = ("surface", "markers")


@dataclass(frozen=True)
class SurfaceTargetsSpec:
    """``[scene.room] targets``: ``count`` markerless targets, points on the room's
    surfaces drawn at run time from the seed (the surfaces the start pose shows both
    cameras, ``depth_m`` deep in H, within ``lateral`` |x/z| and ``vertical`` |y/z|).
    The head is told each only by a click in camera 1's image, ``click_error_px`` its
    standard deviation per axis; camera 2 searches camera 1's row of the point
    +- ``band_px`` (a head that knows no focal length)."""

    count: int
    depth_m: tuple[float, float] = (0.3, 2.0)
    lateral: float = 0.25
    vertical: float = 0.1
    click_error_px: float = 0.5
    band_px: float = 10.0
    #: ``[[scene.room.targets]]``, measured first, in file order
    listed: tuple[ListedSurfaceTarget, ...] = ()
    #: how each is measured (:data:`TARGETS_AS`): by correlation, or by a marker put there
    targets_as: str = "surface"


@dataclass(frozen=True)
class SceneSpec:
    """What is where: ``scene`` is the MJCF scene; ``targets`` to measure (or check
    targets after a calibration); ``chessboard``/``blocks`` the board's top-left inner
    corner or the cross point; ``objects`` for relative positioning; ``parked``
    bodies moved out of sight; ``corners`` the chessboard corners to measure;
    ``acceptance`` how the targets were drawn and which the reach check refused."""

    scene: str
    targets: tuple[Placement, ...] = ()
    chessboard: Placement | None = None
    corners: tuple[int, ...] | None = None
    blocks: Placement | None = None
    objects: tuple[Placement, ...] = ()
    parked: tuple[str, ...] = ()
    moving: MovingTarget | None = None
    pursuit: PursuitSpec | None = None  # for the pursuit procedure
    #: how the targets were drawn and accepted (None: a procedure without targets)
    acceptance: TargetAcceptance | None = None
    #: the textured room put into every scene of the run (``[scene.room]``; None: none)
    room: RoomSpec | None = None
    #: markerless targets on the room's surfaces (``[scene.room] targets``; None: none)
    surface_targets: SurfaceTargetsSpec | None = None


@dataclass(frozen=True)
class Scenario:
    """A checked scenario, ready to run (random parts already drawn from ``seed``).

    ``stored_calibration``: the calibration file ``[experiment.calibration] from``
    names, as the reader read and checked it (None: the scenario has none).
    """

    name: str
    path: Path
    description: str
    seed: int
    fast: bool
    preset: str
    settings: HeadSettings
    settle_mode: str
    scene: SceneSpec
    experiment: ExperimentSpec
    stored_calibration: StoredCalibration | None = field(default=None, compare=False, repr=False)
    #: Where each believed quantity came from (:func:`headsim.sim.settings.belief_sources`;
    #: empty: not known, as for a scenario built in Python; :attr:`believed_from` fills it).
    belief_sources: dict[str, str] = field(default_factory=dict, compare=False, repr=False)

    @property
    def believed_from(self) -> dict[str, str]:
        """Where each believed quantity came from: ``design``, ``preset``, ``file``,
        ``given`` or ``truth`` (equal to the true head's, which the scenario changed)."""
        return self.belief_sources or belief_sources(self.settings)

    @property
    def paper_cameras(self) -> bool:
        """Whether the head has the paper's cameras (its figures are shown beside ours): a
        paper or realistic preset, on a head whose MJCF cameras are not its own."""
        from headsim.sim.model import has_own_cameras

        return self.preset in ("paper", "realistic") and not has_own_cameras(self.settings.head)

    @property
    def fixations(self) -> int:
        """How many fixations the run makes (for the progress bar)."""
        calibration = self.experiment.calibration
        count = calibration.targets if calibration else 0
        return count + registry.get(self.experiment.procedure).fixations(self)


def corner_count() -> int:
    return CHESSBOARD_PATTERN[0] * CHESSBOARD_PATTERN[1]
