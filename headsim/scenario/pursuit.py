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


def _point(table: Table, key: str) -> tuple[float, float, float]:
    value = table.numbers(key, 3, lo=-MAX_COORDINATE_M, hi=MAX_COORDINATE_M, unit="m")
    return (value[0], value[1], value[2])


def _points(table: Table, key: str, minimum: int) -> tuple[tuple[float, float, float], ...]:
    value = table.data.get(key)
    table.has(key)
    allowed = f"an array of at least {minimum} [x, y, z] points, m"
    if not isinstance(value, list) or len(value) < minimum or len(value) > 1000:
        raise table.fail(key, "missing" if value is None else "wrong length or type", allowed)
    points: list[tuple[float, float, float]] = []
    for i, p in enumerate(value):
        if not (isinstance(p, list) and len(p) == 3):
            raise table.fail(f"{key}[{i}]", "must be [x, y, z]", allowed)
        x, y, z = (
            table._check_number(
                f"{key}[{i}]", c, -MAX_COORDINATE_M, MAX_COORDINATE_M, False, False, allowed
            )
            for c in p
        )
        points.append((x, y, z))
    return tuple(points)


def _path(table: Table, seed: int, duration_s: float) -> tuple[str, Path, Visibility]:
    kind = table.choice("kind", PATH_KINDS)
    path: Path
    if kind == "waypoints":
        points = _points(table, "points_world_m", 2)
        speeds = table.data.get("speeds_m_s")
        table.has("speeds_m_s")
        allowed = f"an array of {len(points) - 1} speeds > 0 m/s, one per leg"
        if not isinstance(speeds, list) or len(speeds) != len(points) - 1:
            raise table.fail("speeds_m_s", "missing or wrong length", allowed)
        values = tuple(
            table._check_number(f"speeds_m_s[{i}]", s, 0.0, 100.0, True, False, allowed)
            for i, s in enumerate(speeds)
        )
        path = Waypoints(points, values)
    elif kind == "sinusoid":
        path = Sinusoid(
            _point(table, "centre_world_m"),
            _point(table, "amplitude_m"),
            table.number("frequency_hz", lo=0.0, hi=50.0, lo_open=True, unit="Hz"),
            table.numbers("phase_rad", 3, (0.0, 0.0, 0.0), -10.0, 10.0, unit="rad"),  # type: ignore[arg-type]
        )
    elif kind == "random_walk":
        path = RandomWalk(
            _point(table, "start_world_m"),
            table.number("max_speed_m_s", lo=0.0, hi=10.0, lo_open=True, unit="m/s"),
            duration_s + 1.0,
            seed=table.integer("seed", seed, 0, 2**32 - 1),
            box_half_m=table.numbers("box_half_m", 3, (0.2, 0.2, 0.1), 0.0, 2.0, unit="m"),  # type: ignore[arg-type]
        )
    elif kind == "throw":
        path = Throw(_point(table, "start_world_m"), _point(table, "velocity_m_s"))
    elif kind == "jump":
        path = Jump(
            _point(table, "start_world_m"),
            _point(table, "end_world_m"),
            table.number("time_s", lo=0.0, hi=3600.0, unit="s"),
        )
    else:
        path = Static(_point(table, "point_world_m"))
    windows = table.data.get("windows_s", [])
    table.has("windows_s")
    allowed = "an array of [appear_s, disappear_s] pairs with appear < disappear"
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
    table = scene.table("pursuit")
    if table is None:
        raise scene.fail("pursuit", "missing", "a [scene.pursuit] table")
    name = table.string("name", "pursuit target", 60)
    body = table.choice("body", bodies, bodies[0])
    duration = table.number("duration_s", 3.0, 0.0, 600.0, lo_open=True, unit="s")
    click_error = table.number("click_error_px", 0.5, 0.0, 20.0, unit="px")
    band = table.number("band_px", 10.0, 0.0, 100.0, lo_open=True, unit="px")
    path_table = table.table("path")
    if path_table is None:
        raise table.fail("path", "missing", "a [scene.pursuit.path] table with a kind")
    kind, path, visibility = _path(path_table, seed, duration)
    live = _live(table.table("live"))
    gaze = _gaze(table.table("gaze"))
    table.done()
    return PursuitSpec(name, body, path, kind, visibility, duration, live, gaze, click_error, band)


def _live(table: Table | None) -> LiveConfig:
    if table is None:
        return LiveConfig()
    rate = table.number("frame_rate_hz", 30.0, 1.0, 1000.0, unit="Hz")
    config = LiveConfig(
        frame_rate_hz=rate,
        exposure_s=table.number("exposure_s", 0.0, 0.0, 1.0 / rate, unit="s"),
        blur_subframes=table.integer("blur_subframes", 1, 1, 64),
        latency_frames=table.integer("latency_frames", 1, 0, 30),
        eye_limits=MotorLimits(
            table.number(
                "eye_max_speed", EYE_LIMITS.max_speed, 0.0, 100.0, lo_open=True, unit="rad/s"
            ),
            table.number(
                "eye_max_accel", EYE_LIMITS.max_accel, 0.0, 1e4, lo_open=True, unit="rad/s^2"
            ),
        ),
        neck_limits=MotorLimits(
            table.number(
                "neck_max_speed", NECK_LIMITS.max_speed, 0.0, 100.0, lo_open=True, unit="rad/s"
            ),
            table.number(
                "neck_max_accel", NECK_LIMITS.max_accel, 0.0, 1e4, lo_open=True, unit="rad/s^2"
            ),
        ),
    )
    table.done()
    return config


def _gaze(table: Table | None) -> GazeConfig:
    if table is None:
        return GazeConfig()
    config = GazeConfig(
        mode=GazeMode(table.choice("mode", tuple(m.value for m in GazeMode), "neck")),
        predictor=table.boolean("predictor", True),
        saccade=SaccadeProfile(
            table.choice("saccade", tuple(p.value for p in SaccadeProfile), "min_jerk")
        ),
        saccade_threshold_rad=table.number(
            "saccade_threshold_rad", 0.05, 0.0, 3.0, lo_open=True, unit="rad"
        ),
        fixation_tolerance_px=table.number(
            "fixation_tolerance_px", 1.0, 0.0, 100.0, lo_open=True, unit="px"
        ),
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
