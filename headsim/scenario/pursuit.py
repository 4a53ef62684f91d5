"""The ``pursuit`` procedure's scenario settings: ``[scene.pursuit]`` and its sub-tables.

``[scene.pursuit]``: ``body`` (a marker of the default scene, or an object of
``[scene.room]``: clicked once in camera 1's first image, then tracked without markers,
``click_error_px`` per axis, camera 2 searching camera 1's row +- ``band_px``),
``duration_s``;
``[scene.pursuit.path]``: ``kind`` and that kind's fields (world frame, m, s):

- ``waypoints``: ``points_world_m`` (>= 2 points), ``speeds_m_s`` (one per leg);
- ``sinusoid``: ``centre_world_m``, ``amplitude_m``, ``frequency_hz``, ``phase_rad``;
- ``random_walk``: ``start_world_m``, ``max_speed_m_s``, ``box_half_m``, ``seed``
  (default: the scenario's seed);
- ``throw``: ``start_world_m``, ``velocity_m_s`` (under gravity);
- ``static``: ``point_world_m``;
- ``jump``: ``start_world_m`` until ``time_s``, then at once ``end_world_m`` (a saccade's target);

and ``windows_s`` (``[[appear, disappear], ...]``: when the target is
present; none: always).  ``[scene.pursuit.live]``: ``frame_rate_hz``,
``exposure_s``, ``blur_subframes``, ``latency_frames``, and the motor limits
``eye_max_speed``, ``eye_max_accel``, ``neck_max_speed``, ``neck_max_accel``
(rad/s, rad/s^2).  ``[scene.pursuit.gaze]``: ``mode`` (``neck`` or
``eyes``), ``predictor``, ``saccade`` (``min_jerk`` or ``bang_bang``),
``saccade_threshold_rad``, ``fixation_tolerance_px``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from headsim.live.gaze import GazeConfig, GazeMode, SaccadeProfile
from headsim.live.head import EYE_LIMITS, NECK_LIMITS, LiveConfig
from headsim.live.motors import MotorLimits
from headsim.live.paths import (
    Jump,
    Path,
    RandomWalk,
    Sinusoid,
    Static,
    Throw,
    Visibility,
    Waypoints,
)
from headsim.scenario.tables import Table
from headsim.sim import names
from headsim.sim.declared import Array, Choice, Flag, Section, Setting, Text
from headsim.sim.settings import SettingsError

PATH_KINDS = ("waypoints", "sinusoid", "random_walk", "throw", "static", "jump")
#: Largest coordinate of a path point, m.
MAX_COORDINATE_M = 10.0


@dataclass(frozen=True)
class PursuitSpec:
    """A checked ``[scene.pursuit]``: what moves how, the live head's timing, the gaze controller."""

    name: str
    body: str
    path: Path
    kind: str
    visibility: Visibility
    duration_s: float
    live: LiveConfig
    gaze: GazeConfig
    #: A room object's pursuit: the click's error per axis, px, and the rows +- camera
    #: 2 searches, px (unused for a marker).
    click_error_px: float = 0.5
    band_px: float = 10.0

    def sample_times(self, step_s: float = 0.05) -> np.ndarray:
        """Times at which the path is checked and drawn, s."""
        return np.linspace(0.0, self.duration_s, max(2, round(self.duration_s / step_s) + 1))


def _point(key: str, meaning: str) -> Setting:
    """A point or vector ``[x, y, z]`` of a path, each within +-MAX_COORDINATE_M."""
    unit = "m/s" if key.endswith("_m_s") else "m"
    return Setting(
        key, None, -MAX_COORDINATE_M, MAX_COORDINATE_M, unit, meaning, count=3, required=True
    )


# fmt: off
_AT = "`random_walk`, `throw`, `jump`"
_S, _R = "rad/s", "rad/s^2"
KIND = Choice("kind", PATH_KINDS, None, "The kind of path; each kind takes its own keys below.", required=True)
POINTS = Array("points_world_m", "an array of at least 2 [x, y, z] points, m", "`waypoints`: the points [[x, y, z], ...] in W, m.", required=True)
SPEEDS = Array("speeds_m_s", "an array of speeds > 0 m/s, one per leg", "`waypoints`: the speed along each leg, m/s.", required=True)
CENTRE = _point("centre_world_m", "`sinusoid`: the centre in W, m.")
AMPLITUDE = _point("amplitude_m", "`sinusoid`: the amplitude along x, y, z of W, m.")
FREQUENCY = Setting("frequency_hz", None, 0.0, 50.0, "Hz", "`sinusoid`: the frequency, Hz.", lo_open=True, required=True)
PHASE = Setting("phase_rad", (0.0, 0.0, 0.0), -10.0, 10.0, "rad", "`sinusoid`: the phase along x, y, z, rad.", count=3)
START = _point("start_world_m", f"{_AT}: the start in W, m.")
MAX_SPEED = Setting("max_speed_m_s", None, 0.0, 10.0, "m/s", "`random_walk`: the largest speed, m/s.", lo_open=True, required=True)
WALK_SEED = Setting("seed", None, 0, 2**32 - 1, "", "`random_walk`: the walk's seed; default the scenario's `seed`.", integer=True)
BOX_HALF = Setting("box_half_m", (0.2, 0.2, 0.1), 0.0, 2.0, "m", "`random_walk`: half the box it stays in, along x, y, z, m.", count=3)
VELOCITY = _point("velocity_m_s", "`throw`: the initial velocity in W, m/s (then gravity).")
END = _point("end_world_m", "`jump`: where the target is from `time_s` on, in W, m.")
JUMP_TIME = Setting("time_s", None, 0.0, 3600.0, "s", "`jump`: when the target jumps from the start to the end, s.", required=True)
POINT = _point("point_world_m", "`static`: the point in W, m.")
WINDOWS = Array("windows_s", "an array of [appear_s, disappear_s] pairs with appear < disappear", "When the target is visible: [[appear_s, disappear_s], ...]; default always.", default=())
PATH = Section("scene.pursuit.path", "How the target moves.", (KIND, POINTS, SPEEDS, CENTRE, AMPLITUDE, FREQUENCY, PHASE, START, MAX_SPEED, WALK_SEED, BOX_HALF, VELOCITY, END, JUMP_TIME, POINT, WINDOWS))
RATE = Setting("frame_rate_hz", 30.0, 1.0, 1000.0, "Hz", "Camera frame rate, Hz.")
EXPOSURE = Setting("exposure_s", 0.0, 0.0, 1.0, "s", "Exposure time, s (> 0 with `blur_subframes` > 1: motion blur); at most 1 / `frame_rate_hz`.")
SUBFRAMES = Setting("blur_subframes", 1, 1, 64, "", "Renders averaged per frame for motion blur.", integer=True)
LATENCY = Setting("latency_frames", 1, 0, 30, "", "Frames between an image and the command it causes.", integer=True)
EYE_SPEED = Setting("eye_max_speed", EYE_LIMITS.max_speed, 0.0, 100.0, _S, "Eye motor's speed limit, rad/s.", lo_open=True)
EYE_ACCEL = Setting("eye_max_accel", EYE_LIMITS.max_accel, 0.0, 1e4, _R, "Eye motor's acceleration limit, rad/s^2.", lo_open=True)
NECK_SPEED = Setting("neck_max_speed", NECK_LIMITS.max_speed, 0.0, 100.0, _S, "Neck motors' speed limit, rad/s.", lo_open=True)
NECK_ACCEL = Setting("neck_max_accel", NECK_LIMITS.max_accel, 0.0, 1e4, _R, "Neck motors' acceleration limit, rad/s^2.", lo_open=True)
LIVE = Section("scene.pursuit.live", "The live head's camera and motors.", (RATE, EXPOSURE, SUBFRAMES, LATENCY, EYE_SPEED, EYE_ACCEL, NECK_SPEED, NECK_ACCEL))
MODE = Choice("mode", tuple(m.value for m in GazeMode), "neck", "Model 1 with the neck, or the eyes alone.")
PREDICTOR = Flag("predictor", True, "A constant-velocity predictor against the latency.")
SACCADE = Choice("saccade", tuple(p.value for p in SaccadeProfile), "min_jerk", "Saccade profile: minimum jerk or bang-bang.")
SACCADE_THRESHOLD = Setting("saccade_threshold_rad", 0.05, 0.0, 3.0, "rad", "A fixation correction larger than this starts a saccade, rad.", lo_open=True)
TOLERANCE = Setting("fixation_tolerance_px", 1.0, 0.0, 100.0, "px", "Image error within which the target counts as fixated, px.", lo_open=True)
GAZE = Section("scene.pursuit.gaze", "The gaze behaviour.", (MODE, PREDICTOR, SACCADE, SACCADE_THRESHOLD, TOLERANCE))
NAME = Text("name", "pursuit target", "The pursued target's name.", max_length=60)
BODY = Choice("body", (*names.MARKER_COLOURS, names.CALIBRATION_BALL), names.MARKERS[0], "What moves: a marker body, or a `[[scene.room.objects]]` name (clicked once, then tracked without markers).")
DURATION = Setting("duration_s", 3.0, 0.0, 600.0, "s", "Length of the pursuit, s.", lo_open=True)
CLICK_ERROR = Setting("click_error_px", 0.5, 0.0, 20.0, "px", "A room object's pursuit: the user's click in camera 1's first image, error per axis, px.")
BAND = Setting("band_px", 10.0, 0.0, 100.0, "px", "A room object's pursuit: half-height of the band along camera 1's row in which camera 2 searches, px.", lo_open=True)
PURSUIT = Section("scene.pursuit", "The live head pursuing a moving marker (procedure `pursuit`).", (NAME, BODY, DURATION, CLICK_ERROR, BAND))
#: ``[scene.pursuit]`` and its tables, as the key reference lists them.
SECTIONS = (PURSUIT, PATH, LIVE, GAZE)
# fmt: on


def _path(table: Table, seed: int, duration_s: float) -> tuple[str, Path, Visibility]:
    kind = table.setting(KIND)
    path: Path
    if kind == "waypoints":
        points = table.points(POINTS, 2, 1000, MAX_COORDINATE_M)
        speeds = table.data.get(SPEEDS.name)
        table.has(SPEEDS.name)
        allowed = f"an array of {len(points) - 1} speeds > 0 m/s, one per leg"
        if not isinstance(speeds, list) or len(speeds) != len(points) - 1:
            raise table.fail(SPEEDS.name, "missing or wrong length", allowed)
        values = tuple(
            table._check_number(f"speeds_m_s[{i}]", s, 0.0, 100.0, True, False, allowed)
            for i, s in enumerate(speeds)
        )
        path = Waypoints(points, values)
    elif kind == "sinusoid":
        path = Sinusoid(
            table.setting(CENTRE),
            table.setting(AMPLITUDE),
            table.setting(FREQUENCY),
            table.setting(PHASE),
        )
    elif kind == "random_walk":
        path = RandomWalk(
            table.setting(START),
            table.setting(MAX_SPEED),
            duration_s + 1.0,
            seed=table.setting(WALK_SEED, seed),
            box_half_m=table.setting(BOX_HALF),
        )
    elif kind == "throw":
        path = Throw(table.setting(START), table.setting(VELOCITY))
    elif kind == "jump":
        path = Jump(table.setting(START), table.setting(END), table.setting(JUMP_TIME))
    else:
        path = Static(table.setting(POINT))
    windows = table.data.get(WINDOWS.name, [])
    table.has(WINDOWS.name)
    allowed = WINDOWS.allowed
    if not isinstance(windows, list) or not all(
        isinstance(w, list) and len(w) == 2 for w in windows
    ):
        raise table.fail("windows_s", "must be an array of pairs", allowed)
    pairs = tuple(
        (
            table._check_number(f"windows_s[{i}]", w[0], 0.0, 3600.0, False, False, allowed),
            table._check_number(f"windows_s[{i}]", w[1], 0.0, 3600.0, False, False, allowed),
        )
        for i, w in enumerate(windows)
    )
    try:
        visibility = Visibility(pairs)
    except SettingsError as err:
        raise table.fail("windows_s", str(err), allowed) from err
    table.done()
    return kind, path, visibility


def read_pursuit(scene: Table, seed: int, bodies: tuple[str, ...]) -> PursuitSpec:
    """``[scene.pursuit]`` of a scenario, checked (raises the scenario's ScenarioError)."""
    table = scene.section(PURSUIT)
    if table is None:
        raise scene.fail("pursuit", "missing", "a [scene.pursuit] table")
    name = table.setting(NAME)
    body = table.setting(BODY, bodies[0], choices=bodies)
    duration = table.setting(DURATION)
    click_error = table.setting(CLICK_ERROR)
    band = table.setting(BAND)
    path_table = table.section(PATH)
    if path_table is None:
        raise table.fail("path", "missing", "a [scene.pursuit.path] table with a kind")
    kind, path, visibility = _path(path_table, seed, duration)
    live = _live(table.section(LIVE))
    gaze = _gaze(table.section(GAZE))
    table.done()
    return PursuitSpec(name, body, path, kind, visibility, duration, live, gaze, click_error, band)


def _live(table: Table | None) -> LiveConfig:
    if table is None:
        return LiveConfig()
    rate = table.setting(RATE)
    config = LiveConfig(
        frame_rate_hz=rate,
        exposure_s=table.setting(EXPOSURE, hi=1.0 / rate),
        blur_subframes=table.setting(SUBFRAMES),
        latency_frames=table.setting(LATENCY),
        eye_limits=MotorLimits(table.setting(EYE_SPEED), table.setting(EYE_ACCEL)),
        neck_limits=MotorLimits(table.setting(NECK_SPEED), table.setting(NECK_ACCEL)),
    )
    table.done()
    return config


def _gaze(table: Table | None) -> GazeConfig:
    if table is None:
        return GazeConfig()
    config = GazeConfig(
        mode=GazeMode(table.setting(MODE)),
        predictor=table.setting(PREDICTOR),
        saccade=SaccadeProfile(table.setting(SACCADE)),
        saccade_threshold_rad=table.setting(SACCADE_THRESHOLD),
        fixation_tolerance_px=table.setting(TOLERANCE),
    )
    table.done()
    return config


def describe(spec: PursuitSpec) -> dict[str, Any]:
    """The spec, JSON-ready, for results.json."""
    return {
        "body": spec.body,
        "path_kind": spec.kind,
        "duration_s": spec.duration_s,
        "windows_s": [list(w) for w in spec.visibility.windows],
        "frame_rate_hz": spec.live.frame_rate_hz,
        "exposure_s": spec.live.exposure_s,
        "blur_subframes": spec.live.blur_subframes,
        "latency_frames": spec.live.latency_frames,
        "mode": spec.gaze.mode.value,
        "predictor": spec.gaze.predictor,
        "saccade": spec.gaze.saccade.value,
    }
