"""The schema of the head and the experiment: ``[head]``, ``[cam1]``/``[cam2]``, ``[belief]``,
``[experiment]`` and ``[experiment.calibration]``.

Each key is declared once, beside the field it sets (:mod:`headsim.sim.settings`,
:mod:`headsim.scenario.spec`; the loader's own here), and :func:`declared_keys` lists
them by table: each ``read_*``/``_read_*`` function reads its table's declarations with
:meth:`Table.setting`, and the scenario-key reference is made from the same list.
Missing keys come from the head's preset.  Lengths in metres, angles in radians, pixels
as OpenCV's.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

from headsim.geometry.synthetic import mount_yaw_for_direction
from headsim.paper import INITIAL_DIRECTIONS_RAD
from headsim.procedures import contract as registry
from headsim.scenario.spec import (
    CALIBRATION_DEPTH,
    CALIBRATION_LINES_OF_SIGHT,
    CALIBRATION_POSITIONS,
    CALIBRATION_SETTINGS,
    CALIBRATION_SOURCE,
    CALIBRATION_TARGETS,
    GOAL_COLUMNS,
    INTERPOLATE,
    MAX_DEPTH_M,
    MIDLINE,
    PROCEDURE,
    REMEDY,
    SERVO_SETTINGS,
    CalibrationSpec,
    ExperimentSpec,
    ServoSpec,
)
from headsim.scenario.tables import MISSING, Context, Table, describe_value, short_value
from headsim.sim import heads, imperfections, names
from headsim.sim.declared import Choice, Declared, Setting, Text
from headsim.sim.heads import HeadModel
from headsim.sim.model import design, has_own_cameras, on_head
from headsim.sim.optics import centre_ray_yaw
from headsim.sim.settings import (
    BACKLASH,
    BASELINE,
    BELIEF_SETTINGS,
    COUNT_ERROR,
    ENCODER_RESOLUTION,
    EYE_SETTINGS,
    IMAGE_SETTINGS,
    INITIAL_DIRECTION,
    MOUNT_PITCHES,
    MOUNT_ROLLS,
    MOUNT_YAW,
    MOUNT_YAWS,
    NECK_A2,
    NECK_D1,
    PRESET,
    RENDER_OFFSAMPLES,
    RENDER_SUPERSAMPLE,
    CameraSettings,
    HeadBelief,
    HeadSettings,
    RenderFidelity,
    SettingsError,
    belief_sources,
    camera_values,
    preset,
)

FIRST_TABLES = (
    "description",
    "seed",
    "head",
    "cam1",
    "cam2",
    "belief",
    "scene",
    "experiment",
)

#: The keys of the scenario's top level, ``[head]`` and ``[cam1]``/``[cam2]`` that are
#: declared here, where the loader alone uses them.
DESCRIPTION = Text(
    "description",
    None,
    "One line saying what the experiment is; `headsim list` shows it. Required.",
    required=True,
)
SEED = Setting(
    "seed",
    0,
    0,
    2**32 - 1,
    "",
    "Seed of the image noise and of every random layout; `--seed` replaces it.",
    integer=True,
)
MODEL = Text(
    "model",
    "paper",
    f"Which head: a shipped one ({', '.join(heads.SHIPPED)}) or a path to your head's MJCF file.",
    max_length=1000,
)
SETTLE = Choice(
    "settle",
    ("kinematic", "physics"),
    "kinematic",
    "How joints reach a commanded angle: set kinematically, or driven by MuJoCo's physics.",
)
CAMERA_PRESET = replace(PRESET, meaning="The camera's preset (default: `head.preset`).")
#: ``[head]``'s declared keys in the order it reads them (``model`` and ``[head.mapping]``,
#: which names an MJCF file's parts, are read by :func:`_read_head_model`).
HEAD_KEYS: tuple[Declared, ...] = (
    MODEL,
    PRESET,
    BASELINE,
    NECK_D1,
    NECK_A2,
    ENCODER_RESOLUTION,
    INITIAL_DIRECTION,
    MOUNT_YAWS,
    MOUNT_PITCHES,
    MOUNT_ROLLS,
    SETTLE,
    BACKLASH,
    COUNT_ERROR,
    RENDER_OFFSAMPLES,
    RENDER_SUPERSAMPLE,
)
#: Declared keys whose default the reader takes from other keys (``head.preset``) rather
#: than from a preset's head: the reference says so.
DEFAULT_FROM_OTHER_KEYS: tuple[Declared, ...] = (CAMERA_PRESET, CALIBRATION_LINES_OF_SIGHT)
#: What each declared table means (a procedure's own table is its ``Procedure.keys``'s).
TABLE_MEANINGS = {
    "fast": "Fields merged over the file by `--fast`: tables key by key, other values replaced.",
    "head": "The head's geometry and joints; missing keys come from `head.preset`.",
    "cam1": "One camera's settings; a missing key comes from the camera's preset.",
    "cam2": "One camera's settings; a missing key comes from the camera's preset.",
    "belief": "What the head believes of itself; estimators use only this. Without it: the "
    "realistic preset's design, else the `[head]` values (results.json's `belief.sources` "
    "says which).",
    "experiment": "What is measured and how.",
    "experiment.calibration": "Sec. V before the experiment, in the default scene (required "
    "by `calibration`).",
    "experiment.servo": "The eye and neck servo (`headsim.active.servo_types.ServoConfig`).",
}


def declared_keys() -> tuple[tuple[str, Declared], ...]:
    """Every key declared for the loader, as (its table's path, its declaration): the
    scenario-key reference is made from these (a camera's imperfections as registered now,
    the procedure's choices as registered now)."""
    procedure = replace(PROCEDURE, choices=registry.names())
    return (
        ("", DESCRIPTION),
        ("", SEED),
        *(("head", d) for d in HEAD_KEYS),
        *((f"cam{i}", d) for i in (1, 2) for d in _camera_keys()),
        *(("belief", d) for d in BELIEF_SETTINGS),
        ("experiment", procedure),
        *(("experiment", d) for d in (INTERPOLATE, MIDLINE, REMEDY, GOAL_COLUMNS)),
        ("experiment.calibration", CALIBRATION_POSITIONS),
        *(("experiment.calibration", d) for d in CALIBRATION_SETTINGS),
        *(("experiment.servo", d) for d in SERVO_SETTINGS),
    )


def _camera_keys() -> tuple[Declared, ...]:
    """A camera table's keys, with the imperfections registered now."""
    return (CAMERA_PRESET, *IMAGE_SETTINGS, *imperfections.all_settings(), *EYE_SETTINGS)


#: The image side that bounds each coordinate of the principal point.
_IMAGE_SIDE = {"cx": "width", "cy": "height"}


def _read_camera(
    table: Table | None, index: int, default_preset: str, head: HeadModel
) -> tuple[CameraSettings, str]:
    """``[cam1]``/``[cam2]``: one camera; missing keys from its preset, on ``head``'s own
    camera (:func:`headsim.sim.model.on_head`)."""
    if table is None:
        return on_head(preset(default_preset), head).cameras[index], default_preset
    name = table.setting(CAMERA_PRESET, default_preset)
    base = on_head(preset(name), head).cameras[index]
    values: dict[str, Any] = {}
    for setting in IMAGE_SETTINGS:
        if setting.default is None:  # the principal point: inside this image
            size = values[_IMAGE_SIDE[setting.name]]
            given = getattr(base, setting.name)
            default = given if given is not None and given <= size - 1 else None
            values[setting.name] = table.setting(setting, default, hi=size - 1.0)
        else:
            values[setting.name] = table.setting(setting, getattr(base, setting.name))
    # Every image imperfection's settings, with their declared ranges.
    image_settings = {
        s.name: table.setting(s, base.value(s.name)) for s in imperfections.all_settings()
    }
    for setting in EYE_SETTINGS:
        values[setting.name] = table.setting(setting, getattr(base, setting.name))
    table.done()
    camera = CameraSettings(**values, **camera_values(image_settings))
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


def _read_head_model(head: Table, ctx: Context, directory: Path) -> HeadModel:
    """``head.model`` and ``[head.mapping]``: a shipped head, or an MJCF file and its names."""
    allowed = f"{', '.join(heads.SHIPPED)}, or a path to a head's MJCF .xml file"
    name = head.string("model", "paper", max_length=1000)
    mapping_table = head.table("mapping")
    if name in heads.SHIPPED:
        if mapping_table is not None:
            raise ctx.error(
                "head.mapping",
                f"given for the shipped head {name!r}, which has its own",
                "a mapping only with an MJCF file (head.model = a path to a .xml)",
            )
        return heads.shipped(name)
    path = Path(name)
    path = path if path.is_absolute() else directory / path
    if path.suffix != ".xml" or not path.is_file():
        raise head.fail("model", f"no shipped head or MJCF file {short_value(name)}", allowed)
    if mapping_table is None:
        raise ctx.error(
            "head.mapping",
            "missing for an MJCF head",
            "a [head.mapping] table naming its joints and cameras",
        )
    m = mapping_table
    cameras = m._get(heads.CAMERAS.name)
    if not (
        isinstance(cameras, list)
        and len(cameras) == 2
        and all(isinstance(c, str) and c for c in cameras)
    ):
        raise m.fail(heads.CAMERAS.name, "must name two cameras", heads.CAMERAS.allowed)
    parts = {d.name: m.setting(d) for d in heads.MAPPING.keys if d is not heads.CAMERAS}
    try:
        mapping = heads.HeadMapping(**parts, cameras=(cameras[0], cameras[1]))
    except heads.HeadError as err:
        raise ctx.error(f"head.mapping.{err.key}", err.problem, err.allowed) from None
    m.done()
    return heads.HeadModel(path.stem, path, mapping)


def _designed(model: HeadModel, ctx: Context) -> None:
    """Check the head's mapping against its model, naming the key that fails."""
    if model.is_paper:
        return
    try:
        design(model)
    except heads.HeadError as err:
        raise ctx.error(f"head.mapping.{err.key}", err.problem, err.allowed) from None
    except ValueError as err:  # MuJoCo's own: the file does not load or compile
        # MuJoCo's message runs over lines (the error, then where): one line of its parts.
        parts = [line.strip().rstrip(":") for line in str(err).splitlines() if line.strip()]
        said = "; ".join(parts)[:300] or type(err).__name__
        raise ctx.error(
            "head.model", f"cannot load {model.path}: {said}", "an MJCF file MuJoCo compiles"
        ) from None


def read_head(
    doc: Table, ctx: Context, directory: Path | None = None
) -> tuple[HeadSettings, str, str, dict[str, str]]:
    """``[head]`` with ``[cam1]``, ``[cam2]``, ``[belief]``: the head's settings, preset
    name, settle mode, and where each believed quantity came from (:func:`belief_sources`).

    On another head than the paper's, the lengths start from its design: a preset's
    departure from the paper's design is added to it."""
    head = doc.table("head") or Table({}, "head", ctx)
    head_model = _read_head_model(head, ctx, Path.cwd() if directory is None else directory)
    _designed(head_model, ctx)
    preset_name = head.setting(PRESET)
    base = on_head(preset(preset_name), head_model)
    true = {
        s.name: head.setting(s, getattr(base, s.name))
        for s in (BASELINE, NECK_D1, NECK_A2, ENCODER_RESOLUTION)
    }
    initial = head.setting(INITIAL_DIRECTION)
    yaw = head.setting(MOUNT_YAWS)
    if initial is not None and yaw is not None:
        raise head.fail(
            "mount_yaw_rad", "given together with initial_direction_rad", "one of the two"
        )
    pitch = head.setting(MOUNT_PITCHES)
    roll = head.setting(MOUNT_ROLLS)
    settle = head.setting(SETTLE)
    joints = {s.name: head.setting(s, getattr(base, s.name)) for s in (BACKLASH, COUNT_ERROR)}
    render = {
        s.name: head.setting(s, getattr(base.render, s.name.removeprefix("render_")))
        for s in (RENDER_OFFSAMPLES, RENDER_SUPERSAMPLE)
    }
    head.done()

    own_cameras = has_own_cameras(head_model)  # not the paper's: nor its initial directions
    cameras = []
    for index, key in enumerate(names.CAMERAS):
        camera, camera_preset = _read_camera(doc.table(key), index, preset_name, head_model)
        if initial is not None:
            direction = initial[index]
        elif yaw is None and camera_preset in ("paper", "realistic") and not own_cameras:
            direction = INITIAL_DIRECTIONS_RAD[index]
        else:
            direction = None
        mount_yaw = _mount_yaw(ctx, camera, index, direction, yaw)
        cameras.append(
            replace(
                camera,
                mount_yaw_rad=mount_yaw,
                mount_pitch_rad=pitch[index],
                mount_roll_rad=roll[index],
            )
        )
    belief_table = doc.table("belief")
    try:
        settings = HeadSettings(
            **true,
            **joints,
            cameras=(cameras[0], cameras[1]),
            belief=_read_belief(belief_table, base),
            render=RenderFidelity(
                offsamples=render["render_offsamples"], supersample=render["render_supersample"]
            ),
            head=head_model,
        )
    except SettingsError as err:  # pragma: no cover - the checks above are stricter
        raise ctx.error("head", str(err)) from err
    given = () if belief_table is None else tuple(belief_table.data)
    sources = belief_sources(settings, base, given=given, source="file")
    return settings, preset_name, settle, sources


def _mount_yaw(
    ctx: Context,
    camera: CameraSettings,
    index: int,
    direction: float | None,
    yaws: tuple[float, float] | None,
) -> float:
    """Camera ``index``'s mount yaw: the one that gives it the effective initial
    ``direction`` (None: the raw ``yaws``, else 0), checked against the mount's range."""
    if direction is None:
        mount_yaw = yaws[index] if yaws is not None else 0.0
    else:
        mount_yaw = mount_yaw_for_direction(index + 1, direction, camera.pinhole())
    if not MOUNT_YAW.allows(mount_yaw):
        field_name = "initial_direction_rad" if direction is not None else "mount_yaw_rad"
        raise ctx.error(
            f"head.{field_name}[{index}]",
            f"needs a mount yaw of {mount_yaw:.3f} rad for camera {index + 1}",
            f"a mount yaw within {MOUNT_YAW.range_text()}",
        )
    return mount_yaw


def _read_belief(table: Table | None, base: HeadSettings) -> HeadBelief | None:
    """``[belief]``: what the head believes of its geometry; missing keys from the preset's.

    Without the table (and on presets with no belief of their own) the head is
    believed to be as built: None.
    """
    if table is None:
        return base.belief
    if "nodal_offset_m" in table.data:
        # s = e cos t - n sin t (docs/equations.md): n acts only through the goal column's
        # angle t off the optical axis, which takes the intrinsics the head does not know.
        raise table.fail(
            "nodal_offset_m",
            "no estimate can use a believed forward offset (it acts only through the goal "
            "column's angle off the optical axis, which needs the intrinsics)",
            "leave it out: set the true [cam1]/[cam2] nodal_offset_m, and measure each line "
            "of sight's offset with [experiment.calibration] lines_of_sight = true",
        )
    nominal = base.believed
    values = {s.name: table.setting(s, getattr(nominal, s.name)) for s in BELIEF_SETTINGS}
    table.done()
    return replace(nominal, **values)


def _read_calibration(table: Table | None, lines_default: bool = False) -> CalibrationSpec | None:
    """``[experiment.calibration]``: Sec. V before the experiment."""
    if table is None:
        return None
    positions = _calibration_positions(table)
    defaults = {
        CALIBRATION_TARGETS.name: MISSING if positions is None else len(positions),
        CALIBRATION_LINES_OF_SIGHT.name: lines_default,
    }
    values: dict[str, Any] = {}
    for setting in CALIBRATION_SETTINGS:
        values[setting.name] = table.setting(setting, defaults.get(setting.name, MISSING))
        if setting is CALIBRATION_DEPTH:  # an empty range is named before the keys after it
            check_depth_range(table, values[setting.name])
    spec = CalibrationSpec(
        **{k: v for k, v in values.items() if k != CALIBRATION_SOURCE.name},
        source=values[CALIBRATION_SOURCE.name],
        positions_world_m=positions,
    )
    table.done()
    if positions is not None and spec.targets != len(positions):
        raise table.fail(
            "targets",
            f"{spec.targets} with {len(positions)} positions_world_m",
            "the number of positions_world_m, or no targets",
        )
    if positions is not None and spec.layout != "uniform":
        raise table.fail(
            "layout", f'"{spec.layout}" with positions_world_m', "no layout with given positions"
        )
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


def _calibration_positions(table: Table) -> tuple[tuple[float, float, float], ...] | None:
    """``positions_world_m``: the calibration ball's positions, given (None: drawn)."""
    key, allowed = CALIBRATION_POSITIONS.name, CALIBRATION_POSITIONS.allowed
    value = table.data.get(key)
    table.has(key)
    if value is None:
        return None
    if (
        not isinstance(value, list)
        or not 3 <= len(value) <= 1000
        or not all(isinstance(p, list) and len(p) == 3 for p in value)
    ):
        raise table.fail(
            key, f"must be an array of [x, y, z], got {describe_value(value)}", allowed
        )

    def coordinate(i: int, value: Any) -> float:
        return table._check_number(
            f"{key}[{i}]", value, -MAX_DEPTH_M, MAX_DEPTH_M, False, False, allowed
        )

    return tuple(
        (coordinate(i, p[0]), coordinate(i, p[1]), coordinate(i, p[2])) for i, p in enumerate(value)
    )


def check_depth_range(table: Table, depth_m: tuple[float, float]) -> tuple[float, float]:
    lo, hi = depth_m
    if not lo < hi:
        raise table.fail("depth_m", f"[{lo:g}, {hi:g}] is empty", "[near, far] with near < far")
    return lo, hi


def interpolate_option(table: Table) -> dict[str, Any]:
    """``interpolate``: the fixation angle between the last two encoder steps (Model 1 and 2)."""
    return {INTERPOLATE.name: table.setting(INTERPOLATE)}


def near_midline_options(table: Table) -> dict[str, Any]:
    """``midline_px``, ``remedy_px``: Model 2's near-midline remedy."""
    return {s.name: table.setting(s) for s in (MIDLINE, REMEDY)}


def read_experiment(doc: Table, ctx: Context, preset_name: str = "ideal") -> ExperimentSpec:
    """``[experiment]``: procedure, optional calibration first, and options."""
    table = doc.table("experiment")
    if table is None:
        raise ctx.error("experiment", "missing", "an [experiment] table with a procedure")
    procedure = table.setting(replace(PROCEDURE, choices=registry.names()))
    calibration = _read_calibration(table.table("calibration"), preset_name == "realistic")
    options = registry.get(procedure).options(table, calibration)
    goals = table.setting(GOAL_COLUMNS)
    if goals is not None:
        options["goal_columns_px"] = (goals[0], goals[1])
    servo_table = table.table("servo")
    servo = ServoSpec()
    if servo_table is not None:
        servo = ServoSpec(**{s.name: servo_table.setting(s) for s in SERVO_SETTINGS})
        servo_table.done()
    table.done()
    return ExperimentSpec(procedure, calibration, servo=servo, **options)
