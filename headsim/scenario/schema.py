"""Scenario files: one experiment in TOML, checked where it enters.

A scenario names the head (baseline, neck, encoder, eye mounts), each camera
(image size, focal lengths, principal point, distortion, noise; presets
``ideal`` and ``paper``), the scene (targets, a chessboard, the blocks and
their objects, a moving target; explicit or drawn from a seeded random spec)
and the experiment (which procedure, its options).  :func:`load_scenario`
reads a file, draws the random parts with the seed, checks every field and
every target's reach, and returns a frozen :class:`Scenario`; anything wrong
raises :class:`ScenarioError` with ``FILE: FIELD: what is wrong (allowed:
...)`` before anything is rendered or written.  The schema is this module:
each ``_read_*`` function lists the keys of one table (README "Scenarios and
results" shows them with examples).

Positions are metres in H at the start pose (``position_head_m``: neck and
eyes at 0) or in W (``position_world_m``); angles radians; pixels as OpenCV's.
A ``[fast]`` table holds overrides merged over the file by ``--fast`` (tables
merge key by key, everything else is replaced); both variants are checked.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from functools import cache, lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from headsim.errors import BadInput
from headsim.geometry.kinematics import head_to_world, world_to_head
from headsim.geometry.sampling import sample_points_head
from headsim.scenario.calibration_design import LAYOUTS
from headsim.sim import names
from headsim.sim.model import eye_from_camera_rotation, load_spec
from headsim.sim.optics import centre_ray_yaw
from headsim.sim.settings import (
    MAX_IMAGE_SIDE,
    PAPER_INITIAL_DIRECTIONS,
    CameraSettings,
    HeadBelief,
    HeadSettings,
    RenderFidelity,
    SettingsError,
    preset,
)

#: The narrowest baseline a scenario may set, m: below it vergence carries no depth.
MIN_BASELINE_M = 0.01

#: Where ``headsim list`` and ``headsim run NAME`` look for scenario files.
SCENARIOS_DIR = Path(str(resources.files("headsim") / "scenarios"))

#: Procedure -> the scene (``names.SCENES``) it runs in.
PROCEDURES = {
    "model2": "default",
    "model1": "default",
    "calibration": "default",
    "tracking": "default",
    "chessboard": "chessboard",
    "relative_positioning": "blocks",
    "pursuit": "default",  # the live head (headsim.live.spec)
}
#: Bodies of the default scene that can be measured, and the colour each is found by.
MARKER_BODIES = {**names.MARKER_COLOURS, names.CALIBRATION_BALL: "yellow"}
#: The chessboard of ``headsim/models/scene_chessboard.xml``: inner corners (columns, rows), square, m.
CHESSBOARD_PATTERN = (8, 6)
CHESSBOARD_SQUARE_M = 0.030
#: Nearest a target may be to the head, m (z_h at the start pose).
MIN_DEPTH_M = 0.1
#: Farthest a target may be, m: beyond it one encoder step is centimetres of depth.
MAX_DEPTH_M = 10.0
#: Independent random streams drawn from the scenario seed.
STREAM_CALIBRATION, STREAM_TARGETS, STREAM_OBJECTS, STREAM_MOVING, STREAM_DEPTH_NOISE = range(1, 6)

_MISSING = object()


class ScenarioError(BadInput, ValueError):
    """A scenario file is wrong; the message names the file, the field and what is allowed."""

    def __init__(self, source: str, field_path: str, message: str, allowed: str | None = None):
        self.source, self.field, self.problem, self.allowed = source, field_path, message, allowed
        where = f"{source}: {field_path}: " if field_path else f"{source}: "
        super().__init__(where + message + (f" (allowed: {allowed})" if allowed else ""))


# -- the validated scenario ----------------------------------------------------


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
    directory); the other fields are then not used.
    """

    targets: int = 60
    depth_m: tuple[float, float] = (0.25, 0.6)
    lateral: float = 0.16
    vertical: float = 0.08
    depth_noise_m: float = 0.0
    extended: bool = True
    position_noise_m: float = 0.0
    lines_of_sight: bool = False
    source: str | None = None
    layout: str = "uniform"
    near_fraction: float | None = None


@dataclass(frozen=True)
class ServoSpec:
    """The servo's bounds and tolerances (``headsim.active.servo.ServoConfig``)."""

    tolerance_px: float = 0.1
    max_iterations: int = 25
    probe_steps: int = 16
    min_probe_px: float = 2.0
    min_secant_steps: int = 8


@dataclass(frozen=True)
class ExperimentSpec:
    """Which procedure, the calibration before it, and its options."""

    procedure: str
    calibration: CalibrationSpec | None
    interpolate: bool = True
    midline_px: float = 25.0
    remedy_px: float = 120.0
    servo: ServoSpec = field(default_factory=ServoSpec)
    #: The servo's goal column (u10, u20) of Ca1, Ca2, px, as the user tells the head
    #: (e.g. the principal point's, found with ``headsim.active.principal``); None: image centres.
    goal_columns_px: tuple[float, float] | None = None


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


@dataclass(frozen=True)
class SceneSpec:
    """What is where: ``scene`` is the MJCF scene; ``targets`` to measure (or check
    targets after a calibration); ``chessboard``/``blocks`` the board's top-left inner
    corner or the cross point; ``objects`` for relative positioning; ``parked``
    bodies moved out of sight; ``corners`` the chessboard corners to measure."""

    scene: str
    targets: tuple[Placement, ...] = ()
    chessboard: Placement | None = None
    corners: tuple[int, ...] | None = None
    blocks: Placement | None = None
    objects: tuple[Placement, ...] = ()
    parked: tuple[str, ...] = ()
    moving: MovingTarget | None = None
    pursuit: Any = None  # headsim.live.spec.PursuitSpec for the pursuit procedure


@dataclass(frozen=True)
class Scenario:
    """A checked scenario, ready to run (random parts already drawn from ``seed``)."""

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

    @property
    def paper_cameras(self) -> bool:
        """Whether the head is the paper's preset (its figures are shown beside ours)."""
        return self.preset in ("paper", "realistic")

    @property
    def fixations(self) -> int:
        """How many fixations the run makes (for the progress bar)."""
        calibration = self.experiment.calibration
        count = calibration.targets if calibration else 0
        procedure = self.experiment.procedure
        if procedure == "chessboard":
            return count + len(self.scene.corners or range(_corner_count()))
        if procedure == "relative_positioning":
            return count + 1
        if procedure == "tracking":
            return count + (self.scene.moving.steps if self.scene.moving else 0)
        if procedure == "pursuit":  # one step per camera frame
            pursuit = self.scene.pursuit
            return count + math.ceil(pursuit.duration_s * pursuit.live.frame_rate_hz)
        per_target = 2 if procedure == "calibration" else 1
        return count + per_target * len(self.scene.targets)


def _corner_count() -> int:
    return CHESSBOARD_PATTERN[0] * CHESSBOARD_PATTERN[1]


# -- reading TOML tables -------------------------------------------------------


def _short(value: Any) -> str:
    """A value for a message: long integers and strings shortened."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**15:
        return f"{'-' if value < 0 else ''}an integer of {len(str(abs(value)))} digits"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _describe(value: Any) -> str:
    kind = {bool: "boolean", int: "integer", float: "number", str: "string"}.get(type(value))
    if kind == "integer" and abs(value) >= 10**15:
        return _short(value)
    if kind:
        return f"{kind} {_short(value)}"
    if isinstance(value, list):
        return f"array of {len(value)}"
    if isinstance(value, dict):
        return "table"
    return type(value).__name__


def _range_text(lo: float | None, hi: float | None, lo_open: bool, hi_open: bool, unit: str) -> str:
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {hi:g}")
    text = " and ".join(parts) if parts else "any finite value"
    return f"{text} {unit}".rstrip()


class _Context:
    """Where a document came from, for messages: the file and the fields ``--fast`` set."""

    def __init__(self, source: str, fast_doc: dict[str, Any] | None) -> None:
        self.source = source
        self.fast_doc = fast_doc or {}

    def field_name(self, path: str) -> str:
        """``path``, prefixed with ``fast.`` when the value came from the ``[fast]`` table."""
        node: Any = self.fast_doc
        for part in path.replace("]", "").replace("[", ".").split("."):
            if isinstance(node, dict) and part in node:
                node = node[part]
            elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
                node = node[int(part)]
            else:
                return path
        return f"fast.{path}"

    def error(self, path: str, message: str, allowed: str | None = None) -> ScenarioError:
        return ScenarioError(self.source, self.field_name(path), message, allowed)


class _Table:
    """One TOML table: typed getters that check values, then :meth:`done` rejects the rest."""

    def __init__(self, data: dict[str, Any], path: str, ctx: _Context) -> None:
        self.data, self.path, self.ctx = data, path, ctx
        self.known: list[str] = []

    def field(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        if key not in self.known:
            self.known.append(key)
        return key in self.data

    def _get(self, key: str) -> Any:
        return self.data[key] if self.has(key) else _MISSING

    def fail(self, key: str, message: str, allowed: str | None = None) -> ScenarioError:
        return self.ctx.error(self.field(key), message, allowed)

    def number(
        self,
        key: str,
        default: Any = _MISSING,
        lo: float | None = None,
        hi: float | None = None,
        *,
        lo_open: bool = False,
        hi_open: bool = False,
        unit: str = "",
    ) -> float:
        value = self._get(key)
        allowed = f"a number {_range_text(lo, hi, lo_open, hi_open, unit)}"
        if value is _MISSING:
            if default is _MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        return self._check_number(key, value, lo, hi, lo_open, hi_open, allowed)

    def _check_number(
        self,
        key: str,
        value: Any,
        lo: float | None,
        hi: float | None,
        lo_open: bool,
        hi_open: bool,
        allowed: str,
    ) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(key, f"must be a number, got {_describe(value)}", allowed)
        try:
            value = float(value)
        except OverflowError:  # an integer beyond 1.8e308
            raise self.fail(key, f"{_short(value)} is out of range", allowed) from None
        bad = (
            not math.isfinite(value)
            or (lo is not None and (value <= lo if lo_open else value < lo))
            or (hi is not None and (value >= hi if hi_open else value > hi))
        )
        if bad:
            raise self.fail(key, f"{value:g} is out of range", allowed)
        return value + 0.0  # -0.0 is 0: a range [-x, x] of it must not come out reversed

    def integer(self, key: str, default: Any = _MISSING, lo: int = 0, hi: int = 10**6) -> int:
        value = self._get(key)
        allowed = f"an integer from {lo} to {hi}"
        if value is _MISSING:
            if default is _MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"must be an integer, got {_describe(value)}", allowed)
        if not lo <= value <= hi:
            raise self.fail(key, f"{_short(value)} is out of range", allowed)
        return value

    def boolean(self, key: str, default: bool) -> bool:
        value = self._get(key)
        if value is _MISSING:
            return default
        if not isinstance(value, bool):
            raise self.fail(key, f"must be true or false, got {_describe(value)}", "true, false")
        return value

    def string(self, key: str, default: Any = _MISSING, max_length: int = 200) -> str:
        value = self._get(key)
        allowed = f"one line of text, at most {max_length} characters"
        if value is _MISSING:
            if default is _MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        if not isinstance(value, str):
            raise self.fail(key, f"must be a string, got {_describe(value)}", allowed)
        if not value.strip() or "\n" in value or len(value) > max_length:
            raise self.fail(key, "must be one non-empty line", allowed)
        return value

    def choice(
        self, key: str, allowed: tuple[str, ...] | list[str], default: Any = _MISSING
    ) -> str:
        value = self._get(key)
        text = ", ".join(allowed)
        if value is _MISSING:
            if default is _MISSING:
                raise self.fail(key, "missing", text)
            return default
        if not isinstance(value, str):
            raise self.fail(key, f"must be a string, got {_describe(value)}", text)
        if value not in allowed:
            raise self.fail(key, f"unknown value {_short(value)}", text)
        return value

    def numbers(
        self,
        key: str,
        length: int,
        default: Any = _MISSING,
        lo: float | None = None,
        hi: float | None = None,
        *,
        lo_open: bool = False,
        hi_open: bool = False,
        unit: str = "",
    ) -> tuple[float, ...]:
        value = self._get(key)
        each = _range_text(lo, hi, lo_open, hi_open, unit)
        allowed = f"an array of {length} numbers, each {each}"
        if value is _MISSING:
            if default is _MISSING:
                raise self.fail(key, "missing", allowed)
            return default
        if not isinstance(value, list) or len(value) != length:
            raise self.fail(
                key, f"must be an array of {length} numbers, got {_describe(value)}", allowed
            )
        return tuple(
            self._check_number(f"{key}[{i}]", v, lo, hi, lo_open, hi_open, allowed)
            for i, v in enumerate(value)
        )

    def table(self, key: str) -> _Table | None:
        value = self._get(key)
        if value is _MISSING:
            return None
        if not isinstance(value, dict):
            raise self.fail(
                key, f"must be a table, got {_describe(value)}", f"a [{self.field(key)}] table"
            )
        return _Table(value, self.field(key), self.ctx)

    def tables(self, key: str, max_count: int = 1000) -> list[_Table]:
        value = self._get(key)
        if value is _MISSING:
            return []
        allowed = f"an array of tables, [[{self.field(key)}]], at most {max_count}"
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self.fail(key, f"must be an array of tables, got {_describe(value)}", allowed)
        if len(value) > max_count:
            raise self.fail(key, f"has {len(value)} entries", allowed)
        return [_Table(v, f"{self.field(key)}[{i}]", self.ctx) for i, v in enumerate(value)]

    def done(self) -> None:
        """Reject keys that no getter asked for."""
        for key in self.data:
            if key not in self.known:
                raise self.fail(key, "unknown key", ", ".join(self.known) or "none")


# -- the schema, table by table ---------------------------------------------------

_FIRST_TABLES = (
    "description",
    "seed",
    "head",
    "cam1",
    "cam2",
    "belief",
    "scene",
    "experiment",
)
_PRESETS = ("ideal", "paper", "realistic")


def _read_camera(
    table: _Table | None, index: int, default_preset: str
) -> tuple[CameraSettings, str]:
    """``[cam1]``/``[cam2]``: one camera; missing keys from its preset."""
    if table is None:
        return preset(default_preset).cameras[index], default_preset
    name = table.choice("preset", _PRESETS, default_preset)
    base = preset(name).cameras[index]
    width = table.integer("width", base.width, 16, MAX_IMAGE_SIDE)
    height = table.integer("height", base.height, 16, MAX_IMAGE_SIDE)
    kx = table.number("kx", base.kx, 1.0, 1e5, unit="px")
    ky = table.number("ky", base.ky, 1.0, 1e5, unit="px")
    cx_default = base.cx if base.cx is not None and base.cx <= width - 1 else None
    cy_default = base.cy if base.cy is not None and base.cy <= height - 1 else None
    cx = table.number("cx", cx_default, 0.0, width - 1.0, unit="px (inside the image)")
    cy = table.number("cy", cy_default, 0.0, height - 1.0, unit="px (inside the image)")
    k1 = table.number("k1", base.k1, -1.0, 1.0)
    k2 = table.number("k2", base.k2, -1.0, 1.0)
    noise = table.number("noise_std", base.noise_std, 0.0, 50.0, unit="grey levels")
    nodal = table.number("nodal_offset_m", base.nodal_offset_m, -0.05, 0.1, unit="m")
    side = table.number("side_offset_m", base.side_offset_m, -0.02, 0.02, unit="m")
    tilt = table.number("eye_axis_tilt_rad", base.eye_axis_tilt_rad, -0.1, 0.1, unit="rad")
    table.done()
    camera = CameraSettings(
        width=width,
        height=height,
        kx=kx,
        ky=ky,
        cx=cx,
        cy=cy,
        k1=k1,
        k2=k2,
        noise_std=noise,
        nodal_offset_m=nodal,
        side_offset_m=side,
        eye_axis_tilt_rad=tilt,
    )
    problem = _lens_problem(camera)
    if problem is not None:
        raise table.fail("k1", *problem)
    try:
        centre_ray_yaw(camera)
    except ValueError as err:
        raise table.fail(
            "k1", str(err), "a lens that does not fold over before the image centre"
        ) from err
    return camera, name


def _lens_problem(camera: CameraSettings) -> tuple[str, str] | None:
    """Why the lens gives no ray through the image centre (the servo's aim), in the user's
    terms, with the widest image that works; None when it does."""
    lens = camera.pinhole()
    fold = lens.fold_radius  # undistorted normalised radius where r (1 + k1 r^2 + k2 r^4) peaks
    if not math.isfinite(fold):
        return None
    reach = fold * (1.0 + camera.k1 * fold**2 + camera.k2 * fold**4)  # distorted, same units
    cx, cy = camera.principal
    uc, vc = (camera.width - 1) / 2.0, (camera.height - 1) / 2.0
    du, dv = (uc - cx) / camera.kx, (vc - cy) / camera.ky
    if math.hypot(du, dv) < reach * (1.0 - 1e-9):
        return None
    limit_deg = math.degrees(math.atan(fold))
    room = max((reach - abs(dv)) * (reach + abs(dv)), 0.0) ** 0.5 * camera.kx  # px from cx
    widest = 2.0 * (cx + room) + 1.0
    return (
        f"an image {camera.width} x {camera.height} px with the principal point at "
        f"({cx:g}, {cy:g}) px and kx {camera.kx:g} px puts the image centre "
        f"{math.hypot(du, dv):.3g} focal lengths off axis, beyond where k1 = {camera.k1:g}, k2 = {camera.k2:g} is monotonic "
        f"({reach:.3g} focal lengths, {limit_deg:.0f} degrees off axis): no ray reaches the "
        f"image centre",
        f"for this lens and principal point an image at most {max(int(widest), 0)} px wide "
        f"(or cx, cy near the image centre, or a larger kx)",
    )


def _read_head(doc: _Table, ctx: _Context) -> tuple[HeadSettings, str, str]:
    """``[head]`` with ``[cam1]``, ``[cam2]``: the head's settings, preset name, settle mode."""
    head = doc.table("head") or _Table({}, "head", ctx)
    preset_name = head.choice("preset", _PRESETS, "ideal")
    base = preset(preset_name)
    baseline = head.number(
        "baseline_m",
        base.baseline_m,
        MIN_BASELINE_M,
        1.0,
        unit="m; narrower gives no usable vergence",
    )
    d1 = head.number("neck_d1_m", base.neck_d1_m, 0.0, 2.0, unit="m")
    a2 = head.number("neck_a2_m", base.neck_a2_m, 0.0, 1.0, unit="m")
    resolution = head.number(
        "encoder_resolution_rad", base.encoder_resolution_rad, 0.0, 0.01, lo_open=True, unit="rad"
    )
    mount_range = dict(lo=-0.5, hi=0.5, lo_open=True, hi_open=True, unit="rad")
    initial = head.numbers("initial_direction_rad", 2, None, **mount_range)  # type: ignore[arg-type]
    yaw = head.numbers("mount_yaw_rad", 2, None, **mount_range)  # type: ignore[arg-type]
    if initial is not None and yaw is not None:
        raise head.fail(
            "mount_yaw_rad", "given together with initial_direction_rad", "one of the two"
        )
    pitch = head.numbers("mount_pitch_rad", 2, (0.0, 0.0), **mount_range)  # type: ignore[arg-type]
    roll = head.numbers("mount_roll_rad", 2, (0.0, 0.0), **mount_range)  # type: ignore[arg-type]
    settle = head.choice("settle", ("kinematic", "physics"), "kinematic")
    backlash = head.number("backlash_rad", base.backlash_rad, 0.0, 0.01, unit="rad")
    count_error = head.boolean("count_error", base.count_error)
    offsamples = head.integer("render_offsamples", base.render.offsamples, 0, 16)
    supersample = head.integer("render_supersample", base.render.supersample, 1, 8)
    head.done()

    cameras = []
    for index, key in enumerate(names.CAMERAS):
        camera, camera_preset = _read_camera(doc.table(key), index, preset_name)
        if initial is None and yaw is None and camera_preset in ("paper", "realistic"):
            direction = PAPER_INITIAL_DIRECTIONS[index]
        elif initial is not None:
            direction = initial[index]
        else:
            direction = None
        sign = 1.0 if index == 0 else -1.0
        mount_yaw = (
            (yaw[index] if yaw is not None else 0.0)
            if direction is None
            else direction - sign * centre_ray_yaw(camera)
        )
        field_name = "head.initial_direction_rad" if direction is not None else "head.mount_yaw_rad"
        if not abs(mount_yaw) < 0.5:
            raise ctx.error(
                f"{field_name}[{index}]",
                f"needs a mount yaw of {mount_yaw:.3f} rad for camera {index + 1}",
                "a mount yaw within (-0.5, 0.5) rad",
            )
        cameras.append(
            replace(
                camera,
                mount_yaw_rad=mount_yaw,
                mount_pitch_rad=pitch[index],
                mount_roll_rad=roll[index],
            )
        )
    try:
        settings = HeadSettings(
            baseline_m=baseline,
            neck_d1_m=d1,
            neck_a2_m=a2,
            encoder_resolution_rad=resolution,
            cameras=(cameras[0], cameras[1]),
            backlash_rad=backlash,
            count_error=count_error,
            belief=_read_belief(doc.table("belief"), base),
            render=RenderFidelity(offsamples=offsamples, supersample=supersample),
        )
    except SettingsError as err:  # pragma: no cover - the checks above are stricter
        raise ctx.error("head", str(err)) from err
    return settings, preset_name, settle


def _read_belief(table: _Table | None, base: HeadSettings) -> HeadBelief | None:
    """``[belief]``: what the head believes of its geometry; missing keys from the preset's.

    Without the table (and on presets with no belief of their own) the head is
    believed to be as built: None.
    """
    if table is None:
        return base.belief
    nominal = base.believed
    baseline = table.number("baseline_m", nominal.baseline_m, 0.0, 1.0, lo_open=True, unit="m")
    d1 = table.number("neck_d1_m", nominal.neck_d1_m, 0.0, 2.0, unit="m")
    a2 = table.number("neck_a2_m", nominal.neck_a2_m, 0.0, 1.0, unit="m")
    nodal = table.numbers("nodal_offset_m", 2, nominal.nodal_offset_m, -0.05, 0.1, unit="m")
    side = table.numbers("side_offset_m", 2, nominal.side_offset_m, -0.02, 0.02, unit="m")
    table.done()
    return HeadBelief(
        baseline_m=baseline,
        neck_d1_m=d1,
        neck_a2_m=a2,
        nodal_offset_m=(nodal[0], nodal[1]),
        side_offset_m=(side[0], side[1]),
    )


def _read_calibration(table: _Table | None, lines_default: bool = False) -> CalibrationSpec | None:
    """``[experiment.calibration]``: Sec. V before the experiment."""
    if table is None:
        return None
    spec = CalibrationSpec(
        targets=table.integer("targets", 60, 3, 1000),
        depth_m=_depth_range(table, (0.25, 0.6)),
        lateral=table.number("lateral", 0.16, 0.0, 1.0, lo_open=True, unit="(|x_h / z_h|)"),
        vertical=table.number("vertical", 0.08, 0.0, 1.0, unit="(|y_h / z_h|)"),
        depth_noise_m=table.number("depth_noise_m", 0.0, 0.0, 0.1, unit="m"),
        extended=table.boolean("extended", True),
        position_noise_m=table.number("position_noise_m", 0.0, 0.0, 0.1, unit="m"),
        lines_of_sight=table.boolean("lines_of_sight", lines_default),
        source=table.string("from", None, max_length=1000),
        layout=table.choice("layout", LAYOUTS, "uniform"),
        near_fraction=table.number(
            "near_fraction", None, 0.0, 1.0, lo_open=True, hi_open=True, unit="(share of balls)"
        ),
    )
    table.done()
    if spec.near_fraction is not None and spec.layout != "near_far":
        raise table.fail(
            "near_fraction", f'given with layout = "{spec.layout}"', 'layout = "near_far"'
        )
    if spec.extended and spec.vertical == 0.0:
        raise table.fail(
            "vertical",
            "0 with the extended fit: fitting each camera's reference row and kx/ky needs "
            "ball positions above and below the centre row",
            "a vertical spread > 0 (e.g. 0.08), or extended = false",
        )
    return spec


def _depth_range(table: _Table, default: tuple[float, float]) -> tuple[float, float]:
    lo, hi = table.numbers("depth_m", 2, default, MIN_DEPTH_M, MAX_DEPTH_M, unit="m")
    if not lo < hi:
        raise table.fail("depth_m", f"[{lo:g}, {hi:g}] is empty", "[near, far] with near < far")
    return lo, hi


def _read_experiment(doc: _Table, ctx: _Context, preset_name: str = "ideal") -> ExperimentSpec:
    """``[experiment]``: procedure, optional calibration first, and options."""
    table = doc.table("experiment")
    if table is None:
        raise ctx.error("experiment", "missing", "an [experiment] table with a procedure")
    procedure = table.choice("procedure", tuple(PROCEDURES))
    calibration = _read_calibration(table.table("calibration"), preset_name == "realistic")
    if procedure == "calibration" and calibration is None:
        raise table.fail(
            "calibration", "missing", "an [experiment.calibration] table (the calibration to run)"
        )
    options: dict[str, Any] = {}
    if procedure in ("model2", "model1", "calibration", "chessboard", "tracking"):
        options["interpolate"] = table.boolean("interpolate", True)
    if procedure in ("model2", "calibration", "chessboard"):
        options["midline_px"] = table.number("midline_px", 25.0, 0.0, 1000.0, unit="px")
        options["remedy_px"] = table.number(
            "remedy_px", 120.0, 0.0, 1000.0, lo_open=True, unit="px"
        )
    goals = table.numbers("goal_columns_px", 2, None, 0.0, MAX_IMAGE_SIDE - 1.0, unit="px")
    if goals is not None:
        options["goal_columns_px"] = (goals[0], goals[1])
    servo_table = table.table("servo")
    servo = ServoSpec()
    if servo_table is not None:
        servo = ServoSpec(
            tolerance_px=servo_table.number(
                "tolerance_px", 0.1, 0.0, 10.0, lo_open=True, unit="px"
            ),
            max_iterations=servo_table.integer("max_iterations", 25, 1, 1000),
            probe_steps=servo_table.integer("probe_steps", 16, 1, 10000),
            min_probe_px=servo_table.number(
                "min_probe_px", 2.0, 0.0, 100.0, lo_open=True, unit="px"
            ),
            min_secant_steps=servo_table.integer("min_secant_steps", 8, 1, 1000),
        )
        servo_table.done()
    table.done()
    return ExperimentSpec(procedure, calibration, servo=servo, **options)


def _position(table: _Table, settings: HeadSettings, default: Any = _MISSING) -> np.ndarray:
    """``position_head_m`` (H at the start pose) or ``position_world_m``, as a world point."""
    in_head = table.numbers("position_head_m", 3, None, -MAX_DEPTH_M, MAX_DEPTH_M, unit="m")
    in_world = table.numbers("position_world_m", 3, None, -MAX_DEPTH_M, MAX_DEPTH_M, unit="m")
    allowed = "position_head_m = [x, y, z] (H at the start pose) or position_world_m, not both"
    if in_head is not None and in_world is not None:
        raise table.fail("position_world_m", "given together with position_head_m", allowed)
    if in_head is not None:
        return _head_to_world(settings, np.array(in_head))
    if in_world is not None:
        return np.array(in_world)
    if default is _MISSING:
        raise table.fail("position_head_m", "missing", allowed)
    return np.asarray(default, dtype=float)


def _head_to_world(settings: HeadSettings, points_head: np.ndarray) -> np.ndarray:
    return head_to_world(points_head, 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)


def _random_points_head(table: _Table, count: int, rng: np.random.Generator) -> np.ndarray:
    """Points (count, 3) in H drawn like ``calibration_layout``: depth, then angles."""
    near, far = _depth_range(table, (0.5, 1.2))
    lateral = table.number("lateral", 0.12, 0.0, 1.0, unit="(|x_h / z_h|)")
    vertical = table.number("vertical", 0.06, 0.0, 1.0, unit="(|y_h / z_h|)")
    return sample_points_head(
        rng, count, (-lateral, lateral), (-vertical, vertical), depth_range_m=(near, far)
    )


def _tuple3(p: np.ndarray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))


def _redraw_out_of_reach(
    table: _Table,
    settings: HeadSettings,
    procedure: str,
    body: str,
    points_world: np.ndarray,
    rng: np.random.Generator,
) -> np.ndarray:
    """Points drawn again from the same box until the reach check accepts each (bounded)."""
    head = _Head.of(settings)
    radius = _body_radius(body)

    def refused(p: np.ndarray) -> bool:
        if procedure == "model1":
            return model1_refusal(head, p, "target", True, radius) is not None
        return model2_refusal(head, p, "target", radius) is not None

    points_world = np.array(points_world)
    for k in range(len(points_world)):
        for _ in range(200):
            if not refused(points_world[k]):
                break
            points_world[k] = _head_to_world(settings, _random_points_head(table, 1, rng))[0]
        else:
            raise table.fail(
                "within",
                f"no point of the box within the head's reach in 200 draws (target {k + 1})",
                "a depth_m, lateral and vertical box that overlaps the field both cameras see",
            )
    return points_world


def _read_targets(
    scene: _Table, settings: HeadSettings, seed: int, required: bool, procedure: str = "model2"
) -> tuple[Placement, ...]:
    """``[[scene.targets]]`` and ``[scene.random_targets]``: markers to measure, in turn."""
    bodies = tuple(MARKER_BODIES)
    targets = []
    for k, table in enumerate(scene.tables("targets")):
        name = table.string("name", f"target_{k + 1}", 60)
        body = table.choice("body", bodies, names.MARKERS[0])
        position = _position(table, settings)
        table.done()
        targets.append(Placement(name, body, _tuple3(position), table.path))
    random_table = scene.table("random_targets")
    if random_table is not None:
        count = random_table.integer("count", _MISSING, 1, 1000)
        body = random_table.choice("body", bodies, names.MARKERS[0])
        within = random_table.choice("within", ("box", "reach"), "box")
        rng = np.random.default_rng([seed, STREAM_TARGETS])
        points = _head_to_world(settings, _random_points_head(random_table, count, rng))
        if within == "reach":
            points = _redraw_out_of_reach(random_table, settings, procedure, body, points, rng)
        random_table.done()
        targets += [
            Placement(f"random_{k + 1}", body, _tuple3(p), f"{random_table.path} (target {k + 1})")
            for k, p in enumerate(points)
        ]
    if required and not targets:
        raise scene.fail(
            "targets", "no target to measure", "[[scene.targets]] entries or [scene.random_targets]"
        )
    seen: set[str] = set()
    for placement in targets:
        if placement.name in seen:
            raise scene.ctx.error(
                f"{placement.source}.name", f"{placement.name!r} is used twice", "unique names"
            )
        seen.add(placement.name)
    return tuple(targets)


@cache
def _scene_model(scene: str) -> mujoco.MjModel:
    """The compiled scene as in the XML (joint ranges, default poses); no rendering."""
    return load_spec(scene).compile()


def _default_position(scene: str, body: str) -> np.ndarray:
    model = _scene_model(scene)
    return np.array(model.body(body).pos, dtype=float)


def _read_scene(
    doc: _Table, ctx: _Context, procedure: str, settings: HeadSettings, seed: int
) -> SceneSpec:
    """``[scene]``: what the procedure measures, and where it is."""
    scene_name = PROCEDURES[procedure]
    table = doc.table("scene") or _Table({}, "scene", ctx)
    spec = SceneSpec(scene=scene_name)
    if procedure in ("model2", "model1", "calibration"):
        targets = _read_targets(
            table, settings, seed, required=procedure != "calibration", procedure=procedure
        )
        spec = replace(spec, targets=targets)
    elif procedure == "chessboard":
        spec = _read_chessboard(table, ctx, settings)
    elif procedure == "relative_positioning":
        spec = _read_blocks(table, ctx, settings, seed)
    elif procedure == "tracking":
        spec = replace(spec, moving=_read_moving(table, ctx, settings, seed))
    elif procedure == "pursuit":
        from headsim.live.spec import read_pursuit

        spec = replace(spec, pursuit=read_pursuit(table, seed, tuple(MARKER_BODIES)))
    table.done()
    return spec


def _read_chessboard(table: _Table, ctx: _Context, settings: HeadSettings) -> SceneSpec:
    """``[scene.chessboard]``: where the board's top-left inner corner is; which corners."""
    board = table.table("chessboard") or _Table({}, "scene.chessboard", ctx)
    position = _position(board, settings, _default_position("chessboard", names.CHESSBOARD))
    count = _corner_count()
    corners_value = board.data.get("corners", "all")
    board.has("corners")
    allowed = f'"all" or an array of corner indices 0..{count - 1} (row-major from the top-left)'
    if corners_value == "all":
        corners = None
    elif (
        isinstance(corners_value, list)
        and corners_value
        and all(isinstance(c, int) and not isinstance(c, bool) for c in corners_value)
    ):
        if not all(0 <= c < count for c in corners_value) or len(set(corners_value)) != len(
            corners_value
        ):
            raise board.fail(
                "corners", f"{corners_value} has an index out of range or twice", allowed
            )
        corners = tuple(corners_value)
    else:
        raise board.fail(
            "corners", f'must be "all" or indices, got {_describe(corners_value)}', allowed
        )
    board.done()
    placement = Placement(names.CHESSBOARD, names.CHESSBOARD, _tuple3(position), board.path)
    return SceneSpec(scene="chessboard", chessboard=placement, corners=corners)


def _read_blocks(table: _Table, ctx: _Context, settings: HeadSettings, seed: int) -> SceneSpec:
    """``[scene.blocks]`` (the cross point) and ``[[scene.objects]]``/``[scene.random_objects]``."""
    blocks = table.table("blocks") or _Table({}, "scene.blocks", ctx)
    reference = _position(blocks, settings, _default_position("blocks", names.BLOCKS))
    blocks.done()
    objects: list[Placement] = []
    for entry in table.tables("objects", len(names.RELATIVE_OBJECTS)):
        body = entry.choice("body", names.RELATIVE_OBJECTS)
        position = _position(entry, settings)
        entry.done()
        if any(o.body == body for o in objects):
            raise entry.fail("body", f"{body!r} is placed twice", "each object once")
        objects.append(Placement(body, body, _tuple3(position), entry.path))
    random_table = table.table("random_objects")
    if random_table is not None:
        if objects:
            raise random_table.fail(
                "count", "given together with [[scene.objects]]", "one of the two"
            )
        count = random_table.integer("count", _MISSING, 1, len(names.RELATIVE_OBJECTS))
        rng = np.random.default_rng([seed, STREAM_OBJECTS])
        points = _head_to_world(settings, _random_points_head(random_table, count, rng))
        random_table.done()
        objects = [
            Placement(body, body, _tuple3(p), f"{random_table.path} (object {k + 1})")
            for k, (body, p) in enumerate(zip(names.RELATIVE_OBJECTS, points, strict=False))
        ]
    if not objects:
        objects = [
            Placement(
                body, body, _tuple3(_default_position("blocks", body)), "scene (model default)"
            )
            for body in names.RELATIVE_OBJECTS
        ]
    used = {o.body for o in objects}
    parked = tuple(body for body in names.RELATIVE_OBJECTS if body not in used)
    return SceneSpec(
        scene="blocks",
        blocks=Placement(names.BLOCKS, names.BLOCKS, _tuple3(reference), blocks.path),
        objects=tuple(objects),
        parked=parked,
    )


def _read_moving(table: _Table, ctx: _Context, settings: HeadSettings, seed: int) -> MovingTarget:
    """``[scene.moving_target]``: a marker moved along waypoints, explicit or random."""
    moving = table.table("moving_target")
    if moving is None:
        raise table.fail("moving_target", "missing", "a [scene.moving_target] table")
    name = moving.string("name", "moving_target", 60)
    body = moving.choice("body", tuple(MARKER_BODIES), names.MARKERS[0])
    duration = moving.number("duration_s", 10.0, 0.0, 3600.0, lo_open=True, unit="s")
    steps = moving.integer("steps", _MISSING, 1, 10000)
    allowed = "waypoints_head_m or waypoints_world_m (arrays of [x, y, z], at least 2) or [scene.moving_target.random]"
    given = []
    for key, frame in (("waypoints_head_m", "head"), ("waypoints_world_m", "world")):
        value = moving.data.get(key, _MISSING)
        moving.has(key)
        if value is _MISSING:
            continue
        if (
            not isinstance(value, list)
            or len(value) < 2
            or not all(isinstance(p, list) and len(p) == 3 for p in value)
        ):
            raise moving.fail(
                key, f"must be an array of [x, y, z], got {_describe(value)}", allowed
            )
        points = np.array(
            [[_finite_number(moving, f"{key}[{i}]", c) for c in p] for i, p in enumerate(value)]
        )
        given.append(_head_to_world(settings, points) if frame == "head" else points)
    random_table = moving.table("random")
    if random_table is not None:
        count = random_table.integer("waypoints", _MISSING, 2, 1000)
        rng = np.random.default_rng([seed, STREAM_MOVING])
        given.append(_head_to_world(settings, _random_points_head(random_table, count, rng)))
        random_table.done()
    moving.done()
    if len(given) != 1:
        raise moving.fail("waypoints_head_m", "missing" if not given else "given twice", allowed)
    waypoints = tuple(_tuple3(p) for p in given[0])
    return MovingTarget(name, body, waypoints, duration, steps)


def _finite_number(table: _Table, key: str, value: Any) -> float:
    return table._check_number(
        key, value, -MAX_DEPTH_M, MAX_DEPTH_M, False, False, f"numbers within +-{MAX_DEPTH_M:g} m"
    )


# -- reach: can the head see and fixate it? (geometry only, no rendering) ----------


@dataclass(frozen=True)
class _Head:
    """The head at its start pose: cameras' poses in H, joint ranges, effective directions."""

    settings: HeadSettings
    eye_range: tuple[float, float]
    neck_yaw_range: tuple[float, float]
    neck_pitch_range: tuple[float, float]
    #: Each camera's effective direction (mount yaw and image-centre ray), computed once.
    directions: tuple[float, float]

    @classmethod
    def of(cls, settings: HeadSettings) -> _Head:
        model = _scene_model("base")

        def rng(joint: str) -> tuple[float, float]:
            lo, hi = model.joint(joint).range
            return float(lo), float(hi)

        directions = tuple(
            camera.mount_yaw_rad + sign * centre_ray_yaw(camera)
            for camera, sign in zip(settings.cameras, (1.0, -1.0), strict=True)
        )
        return cls(
            settings,
            rng(names.EYE_MOTOR_JOINT),
            rng(names.NECK_YAW),
            rng(names.NECK_PITCH),
            directions,  # type: ignore[arg-type]
        )

    def effective_direction(self, index: int) -> float:
        """Camera ``index``'s image-centre ray off the head's forward axis at eye 0, rad."""
        return self.directions[index]

    def in_view(
        self, point_head: np.ndarray, index: int, eye: float = 0.0, radius_m: float = 0.0
    ) -> bool:
        """Whether a point projects into camera ``index``'s image at eye angle ``eye``.

        With ``radius_m``, a ball of that radius around it images whole: its
        centre's image is its apparent radius plus 2 px inside the border (what
        the detector needs not to call it cut).
        """
        camera = self.settings.cameras[index]
        sign = 1.0 if index == 0 else -1.0
        centre = np.array([sign * -self.settings.baseline_m / 2, 0.0, 0.0])
        c, s = math.cos(sign * eye), math.sin(sign * eye)
        eye_rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        rotation = eye_rotation @ eye_from_camera_rotation(camera, index)
        p = rotation.T @ (point_head - centre)
        if p[2] <= 0.01:
            return False
        u, v = camera.pinhole().project(p)  # NaN beyond where the lens folds over
        m = 2.0 + max(camera.kx, camera.ky) * radius_m / p[2] if radius_m > 0 else 0.0
        return bool(m <= u <= camera.width - 1 - m and m <= v <= camera.height - 1 - m)

    def model2_angles(self, p: np.ndarray) -> tuple[float, float]:
        """Encoder readings alpha1, alpha2 at which each camera fixates ``p`` (H), rad."""
        half = self.settings.baseline_m / 2
        alpha1 = math.atan2(p[0] + half, p[2]) - self.effective_direction(0)
        alpha2 = math.atan2(half - p[0], p[2]) - self.effective_direction(1)
        return alpha1, alpha2

    def to_head(self, point_world: np.ndarray) -> np.ndarray:
        s = self.settings
        return world_to_head(point_world, 0.0, 0.0, s.neck_d1_m, s.neck_a2_m)


def _fmt(p: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.3f}" for v in p) + "]"


def _check_in_front(ctx: _Context, source: str, p_head: np.ndarray, what: str) -> None:
    if not MIN_DEPTH_M <= p_head[2] <= MAX_DEPTH_M:
        where = "behind or too close to the head" if p_head[2] < MIN_DEPTH_M else "too far"
        raise ctx.error(
            source,
            f"{what} at {_fmt(p_head)} m in H is {where}",
            f"z_h from {MIN_DEPTH_M:g} to {MAX_DEPTH_M:g} m in front of the head",
        )


def _body_radius(body: str | None) -> float:
    """A marker body's sphere radius, m (0 for other bodies)."""
    if body is None:
        return 0.0
    model = _scene_model("default")
    try:
        geom = model.geom(body)
    except KeyError:
        return 0.0
    return float(geom.size[0])


def model2_refusal(
    head: _Head, p_world: np.ndarray, what: str, radius_m: float = 0.0
) -> tuple[str, str] | None:
    """Why Model 2 cannot measure a point (message, what is allowed), or None: it can.

    The criterion the procedure meets (``headsim.active.procedures.measure_model2``
    searches the start pose when a camera loses the target): in front of the
    head, each camera's fixation angle within the eye range, and the target
    seen whole by both cameras at the start pose (neck and eyes at 0).
    """
    p = head.to_head(p_world)
    if not MIN_DEPTH_M <= p[2] <= MAX_DEPTH_M:
        where = "behind or too close to the head" if p[2] < MIN_DEPTH_M else "too far"
        return (
            f"{what} at {_fmt(p)} m in H is {where}",
            f"z_h from {MIN_DEPTH_M:g} to {MAX_DEPTH_M:g} m in front of the head",
        )
    lo, hi = head.eye_range
    for camera, alpha in enumerate(head.model2_angles(p), start=1):
        if not lo <= alpha <= hi:
            return (
                f"{what} at {_fmt(p)} m in H needs an eye angle of {alpha:.3f} rad for "
                f"camera {camera} to fixate it",
                f"targets that both eyes fixate within the eye range [{lo:g}, {hi:g}] rad",
            )
    for index in (0, 1):
        if not head.in_view(p, index, 0.0, radius_m):
            return (
                f"{what} at {_fmt(p)} m in H is not seen whole by camera {index + 1} at the "
                "start pose",
                "a target that both cameras see whole with neck and eyes at 0",
            )
    return None


def _check_model2_reach(
    ctx: _Context,
    head: _Head,
    source: str,
    p_world: np.ndarray,
    what: str,
    radius_m: float = 0.0,
) -> None:
    """Refuse a point that :func:`model2_refusal` refuses, naming the reason."""
    refusal = model2_refusal(head, p_world, what, radius_m)
    if refusal is not None:
        raise ctx.error(source, *refusal)


def _model1_angles(head: _Head, p_world: np.ndarray) -> tuple[float, float, float]:
    """Neck yaw, neck pitch and eye angle that fixate a world point with Model 1, rad."""
    s = head.settings
    yaw = math.atan2(-p_world[0], p_world[1])
    rho, height = math.hypot(p_world[0], p_world[1]), p_world[2] - s.neck_d1_m
    reach = math.hypot(rho, height)
    if reach <= s.neck_a2_m:
        return yaw, math.nan, math.nan
    pitch = math.atan2(height, rho) - math.asin(s.neck_a2_m / reach)
    depth = math.sqrt(max(reach**2 - s.neck_a2_m**2, 0.0))
    eye = math.atan2(s.baseline_m / 2, depth) - 0.5 * (
        head.effective_direction(0) + head.effective_direction(1)
    )
    return yaw, pitch, eye


def model1_refusal(
    head: _Head, p_world: np.ndarray, what: str, start: bool, radius_m: float = 0.0
) -> tuple[str, str] | None:
    """Why Model 1 cannot fixate a point (message, what is allowed), or None: it can.

    Within the neck's and eye's ranges; if ``start`` (a first position, which the
    procedure looks for at the start pose), in front and seen whole by both
    cameras with neck and eyes at 0.
    """
    p = head.to_head(p_world)
    yaw, pitch, eye = _model1_angles(head, p_world)
    if math.isnan(pitch):
        s = head.settings
        distance = math.hypot(math.hypot(p_world[0], p_world[1]), p_world[2] - s.neck_d1_m)
        return (
            f"{what} at {_fmt(np.asarray(p_world))} m in W is {distance:.3f} m from the neck's "
            f"pitch axis, inside the eyes' offset from it (head.neck_a2_m = {s.neck_a2_m:g} m): "
            "no neck pitch turns the eyes towards it",
            "targets farther from the neck's pitch axis than head.neck_a2_m",
        )
    ranges = (
        ("neck yaw", yaw, head.neck_yaw_range),
        ("neck pitch", pitch, head.neck_pitch_range),
        ("eye angle", eye, head.eye_range),
    )
    for label, angle, (lo, hi) in ranges:
        if not lo <= angle <= hi:
            return (
                f"{what} at {_fmt(np.asarray(p_world))} m in W needs a {label} of {angle:.3f} rad",
                f"targets the neck and eyes fixate within their ranges: neck yaw "
                f"[{head.neck_yaw_range[0]:g}, {head.neck_yaw_range[1]:g}], neck pitch "
                f"[{head.neck_pitch_range[0]:g}, {head.neck_pitch_range[1]:g}], eyes "
                f"[{head.eye_range[0]:g}, {head.eye_range[1]:g}] rad",
            )
    if start:
        if not MIN_DEPTH_M <= p[2] <= MAX_DEPTH_M:
            where = "behind or too close to the head" if p[2] < MIN_DEPTH_M else "too far"
            return (
                f"{what} at {_fmt(p)} m in H is {where}",
                f"z_h from {MIN_DEPTH_M:g} to {MAX_DEPTH_M:g} m in front of the head",
            )
        for index in (0, 1):
            if not head.in_view(p, index, 0.0, radius_m):
                return (
                    f"{what} at {_fmt(p)} m in H is not seen whole by camera {index + 1} at "
                    "the start pose",
                    "a first position that both cameras see whole with neck and eyes at 0",
                )
    return None


@lru_cache(maxsize=8)
def _head_of(settings: HeadSettings) -> _Head:
    return _Head.of(settings)


def reach_refusal(
    settings: HeadSettings,
    p_world: np.ndarray,
    what: str = "target",
    radius_m: float = 0.0,
) -> tuple[str, str] | None:
    """The scenario's reach check for one first target, for Model 2 and Model 1 alike.

    (message, what is allowed) from the first model that refuses the world
    point ``p_world``, m, or None: both procedures can measure it from the
    start pose.  The same criterion ``within = "reach"`` applies.
    """
    head = _head_of(settings)
    return model2_refusal(head, p_world, what, radius_m) or model1_refusal(
        head, p_world, what, True, radius_m
    )


def _check_model1_reach(
    ctx: _Context,
    head: _Head,
    source: str,
    p_world: np.ndarray,
    what: str,
    start: bool,
    radius_m: float = 0.0,
) -> None:
    """Refuse a point that :func:`model1_refusal` refuses, naming the reason."""
    refusal = model1_refusal(head, p_world, what, start, radius_m)
    if refusal is not None:
        raise ctx.error(source, *refusal)


def _chessboard_corners_world(placement: Placement, corners: tuple[int, ...] | None) -> np.ndarray:
    """World positions of the chosen inner corners of a board placed at ``placement``."""
    model = _scene_model("chessboard")
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.body(names.CHESSBOARD).quat)
    columns = CHESSBOARD_PATTERN[0]
    indices = range(_corner_count()) if corners is None else corners
    local = np.array(
        [
            [(k % columns) * CHESSBOARD_SQUARE_M, (k // columns) * CHESSBOARD_SQUARE_M, 0.0]
            for k in indices
        ]
    )
    return np.asarray(placement.position_world_m) + local @ rotation.reshape(3, 3).T


def _check_reach(ctx: _Context, scenario: Scenario) -> None:
    head = _Head.of(scenario.settings)
    scene = scenario.scene
    procedure = scenario.experiment.procedure
    for target in scene.targets:
        radius = _body_radius(target.body)
        if procedure == "model1":
            _check_model1_reach(
                ctx,
                head,
                f"{target.source}",
                np.array(target.position_world_m),
                "target",
                True,
                radius,
            )
        else:
            _check_model2_reach(
                ctx, head, target.source, np.array(target.position_world_m), "target", radius
            )
    if scene.chessboard is not None:
        indices = range(_corner_count()) if scene.corners is None else scene.corners
        for k, p in zip(
            indices, _chessboard_corners_world(scene.chessboard, scene.corners), strict=True
        ):
            _check_model2_reach(ctx, head, scene.chessboard.source, p, f"corner {k}")
    if scene.blocks is not None:
        _check_model2_reach(
            ctx, head, scene.blocks.source, np.array(scene.blocks.position_world_m), "cross point"
        )
        for placement in scene.objects:
            p = head.to_head(np.array(placement.position_world_m))
            _check_in_front(ctx, placement.source, p, placement.name)
            if not (head.in_view(p, 0) and head.in_view(p, 1)):
                raise ctx.error(
                    placement.source,
                    f"{placement.name} at {_fmt(p)} m in H is outside a camera's view at the start pose",
                    "objects that both cameras see with neck and eyes at 0",
                )
    if scene.pursuit is not None:
        pursuit = scene.pursuit
        first = True
        for t in pursuit.sample_times():
            if not pursuit.visibility.visible(float(t)):
                continue
            _check_model1_reach(
                ctx,
                head,
                "scene.pursuit.path",
                pursuit.path.position(float(t)),
                f"the target at t = {t:g} s",
                first,
            )
            first = False
    if scene.moving is not None:
        moving = scene.moving
        for k, t in enumerate(moving.times_s):
            _check_model1_reach(
                ctx,
                head,
                "scene.moving_target",
                moving.position(float(t)),
                f"the target at t = {t:g} s",
                k == 0,
                _body_radius(moving.body),
            )


# -- loading ---------------------------------------------------------------------


def _merge(base: dict[str, Any], override: dict[str, Any]) -> dict[str, Any]:
    """``base`` with ``override`` merged in: tables key by key, other values replaced."""
    merged = dict(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = _merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _build(
    doc: dict[str, Any], ctx: _Context, path: Path, fast: bool, seed: int | None
) -> Scenario:
    top = _Table(doc, "", ctx)
    description = top.string("description")
    file_seed = top.integer("seed", 0, 0, 2**32 - 1)
    seed = file_seed if seed is None else seed
    settings, preset_name, settle = _read_head(top, ctx)
    settings = replace(settings, seed=seed)
    experiment = _read_experiment(top, ctx, preset_name)
    calibration = experiment.calibration
    if calibration is not None and calibration.source is not None:
        from headsim.active.calibration_file import CalibrationFileError, read_calibration

        source = Path(calibration.source)
        if not source.is_absolute():  # relative to the scenario file, like the file's own paths
            source = path.parent / source
            experiment = replace(experiment, calibration=replace(calibration, source=str(source)))
        try:
            read_calibration(source, settings)
        except CalibrationFileError as err:
            raise ctx.error("experiment.calibration.from", str(err)) from err
    if experiment.goal_columns_px is not None and calibration and calibration.source:
        raise ctx.error(
            "experiment.goal_columns_px",
            "given with experiment.calibration.from",
            "one of the two (a calibration file carries its own goal columns)",
        )
    for index, u in enumerate(experiment.goal_columns_px or ()):
        width = settings.cameras[index].width
        if not u <= width - 1:
            raise ctx.error(
                f"experiment.goal_columns_px[{index}]",
                f"{u:g} px is outside camera {index + 1}'s image",
                f"a column in [0, {width - 1}] px",
            )
    scene = _read_scene(top, ctx, experiment.procedure, settings, seed)
    top.has("fast")
    top.done()
    scenario = Scenario(
        name=path.stem,
        path=path,
        description=description,
        seed=seed,
        fast=fast,
        preset=preset_name,
        settings=settings,
        settle_mode=settle,
        scene=scene,
        experiment=experiment,
    )
    _check_servo(ctx, scenario)
    _check_reach(ctx, scenario)
    return scenario


def _check_servo(ctx: _Context, scenario: Scenario) -> None:
    """The servo's probe must fit in the eye's range (a probe step moves both eyes)."""
    lo, hi = _Head.of(scenario.settings).eye_range
    resolution = scenario.settings.encoder_resolution_rad
    half_range = (hi - lo) / 2.0
    steps = scenario.experiment.servo.probe_steps
    if steps * resolution > half_range:
        raise ctx.error(
            "experiment.servo.probe_steps",
            f"{steps} encoder steps of {resolution:.3g} rad turn the eyes by "
            f"{steps * resolution:.3g} rad, more than they can turn from the centre of their "
            f"range [{lo:g}, {hi:g}] rad",
            f"at most {int(half_range / resolution)} steps",
        )


def resolve_path(name_or_path: str | Path) -> Path:
    """A scenario file: a path, or the name of a file in ``headsim/scenarios/`` (without .toml)."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    candidate = SCENARIOS_DIR / f"{name_or_path}.toml"
    if isinstance(name_or_path, str) and "/" not in name_or_path and candidate.is_file():
        return candidate
    available = ", ".join(p.stem for p in scenario_files()) or "none"
    raise ScenarioError(
        str(name_or_path), "", "no such scenario file", f"a .toml path or one of: {available}"
    )


def _drop_field(doc: dict[str, Any], dotted: str) -> dict[str, Any]:
    head, _, rest = dotted.partition(".")
    if head not in doc:
        return doc
    out = dict(doc)
    if not rest:
        del out[head]
    elif isinstance(out[head], dict):
        out[head] = _drop_field(out[head], rest)
    return out


def set_field(doc: dict[str, Any], dotted: str, value: Any) -> dict[str, Any]:
    """A copy of ``doc`` with the field at ``dotted`` (e.g. ``"cam1.kx"``) set to ``value``."""
    head, _, rest = dotted.partition(".")
    out = dict(doc)
    if not rest:
        out[head] = value
        return out
    child = out.get(head, {})
    if not isinstance(child, dict):
        raise ValueError(f"{dotted}: {head} is not a table")
    out[head] = set_field(child, rest, value)
    return out


def load_scenario(
    name_or_path: str | Path,
    *,
    fast: bool = False,
    seed: int | None = None,
    overrides: dict[str, Any] | None = None,
) -> Scenario:
    """Read, merge ``[fast]`` if asked, draw the random parts, check everything.

    Both the full and the fast variant are checked, whichever is returned.
    ``seed`` overrides the file's ``seed``; ``overrides`` sets fields by
    dotted name (``{"cam1.kx": 700.0}``) in both variants, checked like the
    file's own.  Raises :class:`ScenarioError`.
    """
    path = resolve_path(name_or_path)
    source = str(path)
    doc = read_toml(path)
    try:
        return _load(doc, path, fast=fast, seed=seed, overrides=overrides)
    except RecursionError as err:  # a structure nested too deeply for the checks
        raise ScenarioError(
            source, "", f"nested too deeply{_deep_line(_text_or_empty(path))}"
        ) from err


#: Deepest nesting of arrays and inline tables a scenario file may have.
MAX_NESTING = 50
#: Most digits an integer in a scenario file may have (Python's int() limit is 4300).
MAX_DIGITS = 4300


def read_toml(path: Path) -> dict[str, Any]:
    """Parse a TOML file; any failure (syntax, nesting, huge integers, encoding) is a
    :class:`ScenarioError` naming the line.  A UTF-8 byte-order mark is allowed."""
    source = str(path)
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = path.read_bytes()[: err.start].count(b"\n") + 1
        raise ScenarioError(source, "", f"line {line}: not UTF-8 text ({err.reason})") from err
    except OSError as err:
        raise ScenarioError(source, "", f"cannot be read: {err.strerror or err}") from err
    deep = _deep_line(text)
    if deep:
        raise ScenarioError(
            source, "", f"arrays or inline tables nested too deeply{deep}",
            f"at most {MAX_NESTING} levels",
        )  # fmt: skip
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        last = text.count("\n") + (0 if text.endswith("\n") else 1)
        reason = str(err).replace("(at end of document)", f"(at line {last}, the end of the file)")
        raise ScenarioError(source, "", f"not valid TOML: {reason}", "TOML 1.0") from err
    except RecursionError as err:
        raise ScenarioError(source, "", "nested too deeply for the TOML parser") from err
    except ValueError as err:  # int() refuses more than 4300 digits
        line = _long_number_line(text)
        raise ScenarioError(
            source, "", f"{line}a number with too many digits ({err})",
            f"integers of at most {MAX_DIGITS} digits",
        ) from err  # fmt: skip


def _text_or_empty(path: Path) -> str:
    try:
        return path.read_bytes().decode("utf-8-sig", errors="replace")
    except OSError:
        return ""


def _deep_line(text: str) -> str:
    """``" at line N"`` where brackets nest deeper than :data:`MAX_NESTING`, else ``""``.

    Counts ``[`` and ``{`` outside strings and comments; a table header's ``[[``
    adds at most two levels, far below the limit.
    """
    depth, line, quote, comment = 0, 1, "", False
    for index, char in enumerate(text):
        if char == "\n":
            line, comment = line + 1, False
            if quote in ('"', "'"):
                quote = ""
            continue
        if comment:
            continue
        if quote:
            if char == quote[0] and not (quote == '"' and text[index - 1] == "\\"):
                quote = ""
            continue
        if char == "#":
            comment = True
        elif char in "\"'":
            quote = char
        elif char in "[{":
            depth += 1
            if depth > MAX_NESTING:
                return f" at line {line}"
        elif char in "]}":
            depth = max(depth - 1, 0)
    return ""


def _long_number_line(text: str) -> str:
    match = re.search(rf"[0-9_]{{{MAX_DIGITS + 1},}}", text)
    if match is None:
        return ""
    return f"line {text.count(chr(10), 0, match.start()) + 1}: "


def _load(
    doc: dict[str, Any],
    path: Path,
    *,
    fast: bool,
    seed: int | None,
    overrides: dict[str, Any] | None,
) -> Scenario:
    source = str(path)
    if seed is not None and not (isinstance(seed, int) and 0 <= seed < 2**32):
        raise ScenarioError(
            source, "seed", f"{seed!r} is out of range", "an integer from 0 to 2**32 - 1"
        )
    for dotted, value in (overrides or {}).items():
        try:
            doc = set_field(doc, dotted, value)
        except ValueError as err:
            raise ScenarioError(source, dotted, f"cannot be set: {err}") from err
    fast_doc = doc.get("fast", {})
    if overrides and isinstance(fast_doc, dict):
        # An override wins over the fast table's value for the same field.
        for dotted in overrides:
            fast_doc = _drop_field(fast_doc, dotted)
    if not isinstance(fast_doc, dict):
        raise ScenarioError(
            source,
            "fast",
            f"must be a table, got {_describe(fast_doc)}",
            "a [fast] table of overrides",
        )
    for key in fast_doc:
        if key not in _FIRST_TABLES or key == "description":
            allowed = ", ".join(k for k in _FIRST_TABLES if k != "description")
            raise ScenarioError(source, f"fast.{key}", "unknown key", allowed)
    full = _build(doc, _Context(source, None), path, False, seed)
    quick = _build(_merge(doc, fast_doc), _Context(source, fast_doc), path, True, seed)
    return quick if fast else full


def scenario_files(directory: Path | None = None) -> list[Path]:
    """The scenario files in ``directory`` (default ``headsim/scenarios/``), sorted by name."""
    directory = SCENARIOS_DIR if directory is None else directory
    return sorted(directory.glob("*.toml")) if directory.is_dir() else []


def describe_scenarios(directory: Path | None = None) -> Iterator[tuple[str, str]]:
    """(name, description) of each scenario file; an unreadable file says why."""
    for path in scenario_files(directory):
        try:
            yield path.stem, load_scenario(path).description
        except ScenarioError as err:
            yield path.stem, f"INVALID: {err}"
        except Exception as err:  # one unreadable file must not end the listing
            yield path.stem, f"INVALID: cannot be checked: {type(err).__name__}: {err}"


__all__ = [
    "MARKER_BODIES",
    "PROCEDURES",
    "SCENARIOS_DIR",
    "CalibrationSpec",
    "ExperimentSpec",
    "MovingTarget",
    "Placement",
    "Scenario",
    "ScenarioError",
    "SceneSpec",
    "ServoSpec",
    "describe_scenarios",
    "load_scenario",
    "reach_refusal",
    "resolve_path",
    "scenario_files",
]
