"""Settings of the simulated head and its cameras, checked where they enter.

Units: metres, radians, pixels.  Pixel coordinates follow OpenCV: the centre of
pixel (i, j) is at (i, j), so the geometric centre of a W x H image is
((W - 1) / 2, (H - 1) / 2) -- the paper's (320, 240) for 640 x 480.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from headsim.errors import BadInput
from headsim.geometry.camera_model import PinholeCamera, image_centre
from headsim.geometry.synthetic import mount_yaw_for_direction
from headsim.paper import BASELINE_M, ENCODER_RESOLUTION_RAD, INITIAL_DIRECTIONS_RAD, INTRINSICS
from headsim.sim import imperfections
from headsim.sim.declared import Choice, Flag, Setting
from headsim.sim.heads import MODELS_DIR, PAPER, HeadMapping, HeadModel
from headsim.sim.imperfections.distortion import K1, K2
from headsim.sim.imperfections.noise import NOISE_STD
from headsim.sim.tolerances import REALISTIC_BUDGET

#: Largest image side the off-screen buffer is allowed to grow to, px.
MAX_IMAGE_SIDE = 4096
#: Focal length of the ideal camera: 640 x 480 with a 45 degree vertical field, px.
IDEAL_FOCAL_PX = 240.0 / math.tan(math.radians(22.5))


class SettingsError(BadInput, ValueError):
    """A setting is out of its allowed range; the message names it."""


def _check(condition: bool, message: str) -> None:
    if not condition:
        raise SettingsError(message)


def _finite(name: str, value: float) -> None:
    _check(
        isinstance(value, (int, float)) and math.isfinite(value),
        f"{name} must be a finite number, got {value!r}",
    )


#: A camera's own settings (those of its image imperfections are declared with each
#: imperfection): the one declaration of each one's range, default, unit and meaning, which
#: :class:`CameraSettings`'s checks, the scenario schema and the scenario-key reference read.
WIDTH = Setting("width", 640, 16, MAX_IMAGE_SIDE, "px", "Image width, px.", integer=True)
HEIGHT = Setting("height", 480, 16, MAX_IMAGE_SIDE, "px", "Image height, px.", integer=True)
KX = Setting("kx", IDEAL_FOCAL_PX, 1.0, 1e5, "px", "Focal length along the image's u axis, px.")
KY = Setting("ky", IDEAL_FOCAL_PX, 1.0, 1e5, "px", "Focal length along the image's v axis, px.")
#: The principal point: its default (None) is the image centre, and it must lie inside the
#: image, which the range here (any image's) only bounds.
CX = Setting(
    "cx",
    None,
    0.0,
    MAX_IMAGE_SIDE - 1,
    "px",
    "Principal point's column, px (pixel centres at integer coordinates).",
    unit_note=" (inside the image)",
)
CY = Setting(
    "cy",
    None,
    0.0,
    MAX_IMAGE_SIDE - 1,
    "px",
    "Principal point's row, px.",
    unit_note=" (inside the image)",
)


def _mount_angle(name: str, meaning: str) -> Setting:
    """A tilt of the camera on its eye, set per eye in ``[head]`` (within 0.5 rad, so that
    the two eyes' fields still overlap)."""
    return Setting(name, 0.0, -0.5, 0.5, "rad", meaning, lo_open=True, hi_open=True)


MOUNT_YAW = _mount_angle(
    "mount_yaw_rad", "The eye's initial direction alpha_e (positive inward, like the eye angle)."
)
MOUNT_PITCH = _mount_angle("mount_pitch_rad", "The camera's pitch on its eye (0 in the paper).")
MOUNT_ROLL = _mount_angle("mount_roll_rad", "The camera's roll on its eye (0 in the paper).")
NODAL_OFFSET = Setting(
    "nodal_offset_m",
    0.0,
    -0.05,
    0.1,
    "m",
    "Optical centre in front of the eye's yaw axis, m (lenses: 0.01-0.03).",
)
SIDE_OFFSET = Setting(
    "side_offset_m",
    0.0,
    -0.02,
    0.02,
    "m",
    "Optical centre along the camera's x from the yaw axis, m (mounting: up to 0.002).",
)
EYE_AXIS_TILT = Setting(
    "eye_axis_tilt_rad",
    0.0,
    -0.1,
    0.1,
    "rad",
    "The eye's yaw axis leaning forward, rad (machining: a few mrad).",
)


#: The mount's angles as a scenario's ``[head]`` sets them, one per eye (the yaw given
#: either raw or as the eye's effective initial direction, not both).
INITIAL_DIRECTION = replace(
    MOUNT_YAW,
    name="initial_direction_rad",
    default=None,
    count=2,
    optional=True,
    meaning="Each eye's effective initial direction alpha_ei, rad (or `mount_yaw_rad`, not both).",
)
MOUNT_YAWS = replace(
    MOUNT_YAW,
    default=None,
    count=2,
    optional=True,
    meaning="Each eye's raw mount yaw, rad (or `initial_direction_rad`, not both).",
)
MOUNT_PITCHES = replace(
    MOUNT_PITCH, default=(0.0, 0.0), count=2, meaning="Each eye's mount pitch, rad."
)
MOUNT_ROLLS = replace(
    MOUNT_ROLL, default=(0.0, 0.0), count=2, meaning="Each eye's mount roll, rad."
)


#: The camera's image and lens, in the order a scenario's ``[cam1]``/``[cam2]`` reads them.
IMAGE_SETTINGS = (WIDTH, HEIGHT, KX, KY, CX, CY)
#: Where the optical centre sits on the eye, in the order a scenario's camera table reads them.
EYE_SETTINGS = (NODAL_OFFSET, SIDE_OFFSET, EYE_AXIS_TILT)
#: The mount's angles, set per eye in a scenario's ``[head]``.
MOUNT_SETTINGS = (MOUNT_YAW, MOUNT_PITCH, MOUNT_ROLL)
#: Every setting of :class:`CameraSettings` declared here (the imperfections' are declared
#: with them).
CAMERA_SETTINGS = (*IMAGE_SETTINGS, *MOUNT_SETTINGS, *EYE_SETTINGS)
#: A camera's numeric settings, each checked to be finite; their order is also the
#: order in which the Gymnasium environment draws them (headsim.envs.fixate).
CAMERA_NUMBER_FIELDS = (
    "kx",
    "ky",
    "k1",
    "k2",
    "mount_yaw_rad",
    "mount_pitch_rad",
    "mount_roll_rad",
    "noise_std",
    "nodal_offset_m",
    "side_offset_m",
    "eye_axis_tilt_rad",
)


@dataclass(frozen=True)
class CameraSettings:
    """One eye camera: image size, pinhole intrinsics, lens and mount.

    ``cx``/``cy`` default to the image centre.  ``k1``/``k2`` are OpenCV's radial
    coefficients on normalised coordinates.  ``mount_yaw_rad`` is the paper's
    alpha_e (the eye's initial direction, positive inward like the eye angle);
    ``mount_pitch_rad``/``mount_roll_rad`` tilt the camera on its eye (0 in the
    paper).  The image imperfections' settings (``k1``, ``k2``, ``noise_std`` and
    those of any other registered imperfection, kept in ``extra``) are declared,
    with their ranges and meanings, in their modules (:mod:`headsim.sim.imperfections`);
    :meth:`value` reads any of them.

    Beyond the paper (issue 10, a real head): ``nodal_offset_m`` puts the
    optical centre that far in front of the eye's yaw axis, along the optical
    axis (a lens's entrance pupil: typically 0.01-0.03 m); ``side_offset_m``
    along the camera's x (right) (mounting: typically |.| <= 0.002 m);
    ``eye_axis_tilt_rad`` leans the eye's yaw axis forward, about H's x
    (typically |.| <= 0.005 rad).  All default to 0, the paper's ideal eye.
    The lens itself is :meth:`pinhole`'s :class:`PinholeCamera` (projection,
    distortion, image centre): this class adds the mount, noise and checks.
    """

    width: int = int(WIDTH.fixed_default)
    height: int = int(HEIGHT.fixed_default)
    kx: float = KX.fixed_default
    ky: float = KY.fixed_default
    cx: float | None = None
    cy: float | None = None
    k1: float = K1.fixed_default
    k2: float = K2.fixed_default
    mount_yaw_rad: float = MOUNT_YAW.fixed_default
    mount_pitch_rad: float = MOUNT_PITCH.fixed_default
    mount_roll_rad: float = MOUNT_ROLL.fixed_default
    noise_std: float = NOISE_STD.fixed_default
    nodal_offset_m: float = NODAL_OFFSET.fixed_default
    side_offset_m: float = SIDE_OFFSET.fixed_default
    eye_axis_tilt_rad: float = EYE_AXIS_TILT.fixed_default
    #: Settings of imperfections registered beyond the fields above, as (name, value)
    #: pairs (left out of the records while empty; see :func:`settings_record`).
    extra: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        for setting in CAMERA_SETTINGS:
            value = getattr(self, setting.name)
            if value is not None:  # cx, cy: None is the image centre
                problem = setting.check(value)
                _check(problem is None, str(problem))
        for name, size in (("cx", self.width), ("cy", self.height)):
            value = getattr(self, name)
            if value is not None:
                _check(
                    0 <= value <= size - 1,
                    f"principal point {name} = {value} px lies outside the image [0, {size - 1}]",
                )
        declared = {s.name for s in imperfections.all_settings()} - _CAMERA_FIELDS
        names = [name for name, _ in self.extra]
        _check(
            all(name in declared for name in names) and len(set(names)) == len(names),
            f"camera extra must be (name, value) pairs of registered imperfection settings "
            f"other than its fields ({', '.join(sorted(declared)) or 'none'}), got {self.extra!r}",
        )
        for setting in imperfections.all_settings():
            problem = setting.check(self.value(setting.name))
            _check(problem is None, str(problem))

    def value(self, name: str) -> float:
        """The value of imperfection setting ``name``: its field, its ``extra`` entry, or
        its declared default."""
        if name in _CAMERA_FIELDS:
            return float(getattr(self, name))
        for key, value in self.extra:
            if key == name:
                return value
        return imperfections.setting(name).fixed_default

    @property
    def principal(self) -> tuple[float, float]:
        """Principal point (cx, cy), px, OpenCV pixel convention."""
        u, v = self.image_centre
        return (u if self.cx is None else self.cx, v if self.cy is None else self.cy)

    @property
    def image_centre(self) -> tuple[float, float]:
        """Geometric centre of the image, px: ((W - 1) / 2, (H - 1) / 2)."""
        return image_centre(self.width, self.height)

    def pinhole(self) -> PinholeCamera:
        """The camera's true intrinsics as a :class:`headsim.geometry.camera_model.PinholeCamera`."""
        cx, cy = self.principal
        return PinholeCamera(self.width, self.height, self.kx, self.ky, cx, cy, self.k1, self.k2)

    def with_zoom(self, factor: float) -> CameraSettings:
        """The same camera with both focal lengths scaled by ``factor``."""
        _check(factor > 0, f"zoom factor must be > 0, got {factor}")
        return replace(self, kx=self.kx * factor, ky=self.ky * factor)


_CAMERA_FIELDS = frozenset(f.name for f in fields(CameraSettings))


def camera_values(values: dict[str, float]) -> dict[str, Any]:
    """Imperfection settings by name as :class:`CameraSettings` arguments: its fields,
    and the rest as ``extra`` (those at their declared default left out, so that a
    camera's record is the same whatever else is registered)."""
    own = {k: v for k, v in values.items() if k in _CAMERA_FIELDS}
    extra = tuple(
        (k, v)
        for k, v in values.items()
        if k not in _CAMERA_FIELDS and v != imperfections.setting(k).default
    )
    return {**own, "extra": extra} if extra else own


RENDER_OFFSAMPLES = Setting(
    "render_offsamples",
    4,
    0,
    16,
    "",
    "MuJoCo multisampling per pixel (Mesa caps it at 4).",
    integer=True,
)
RENDER_SUPERSAMPLE = Setting(
    "render_supersample",
    2,
    1,
    8,
    "",
    "Render this many times larger and area-average down (1: faster, coarser).",
    integer=True,
)
#: :class:`RenderFidelity`'s settings, as a scenario's ``[head]`` names them.
RENDER_SETTINGS = (RENDER_OFFSAMPLES, RENDER_SUPERSAMPLE)


@dataclass(frozen=True)
class RenderFidelity:
    """How finely the eye images are rendered: the one knob for edge accuracy.

    ``offsamples``: MuJoCo's multisampling of the off-screen buffer (0 = none;
    4 puts edges on a quarter-pixel grid).  ``supersample``: each image is
    rendered at this many times its resolution (focal lengths scaled, pixel
    centres kept) and area-averaged back down (1 = off).  Windowed renderers
    must render at the same ratio.  The default, (4, 2), is every preset's:
    a marker-centroid floor of 0.032 px (95th percentile over 200 sub-pixel
    poses; 0.078 px at (4, 1)) and a chessboard-corner floor of 0.082 px
    (0.158), at about 1.4x the render time of (4, 1):
    benchmarks/render_fidelity.py.  ``RenderFidelity(4, 1)`` is the earlier,
    faster default.
    """

    offsamples: int = int(RENDER_OFFSAMPLES.fixed_default)
    supersample: int = int(RENDER_SUPERSAMPLE.fixed_default)

    def __post_init__(self) -> None:
        for setting in RENDER_SETTINGS:
            problem = setting.check(getattr(self, setting.name.removeprefix("render_")))
            _check(problem is None, str(problem))


#: Rendering whose marker-centroid floor is <= 0.05 px: the default (see :class:`RenderFidelity`).
FINE_RENDERING = RenderFidelity(offsamples=4, supersample=2)


#: The true head's own numbers, each declared once (range, default, unit, meaning): read by
#: :class:`HeadSettings`'s checks, the scenario schema's ``[head]`` and the key reference.
BASELINE = Setting(
    "baseline_m",
    BASELINE_M,
    0.01,
    1.0,
    "m",
    "True distance between the eyes' yaw axes (the optical centres, on them), m. Without "
    "`[belief]` the ideal and paper presets believe it too (`belief.sources`: `truth`).",
    unit_note="; narrower gives no usable vergence",
)
NECK_D1 = Setting(
    "neck_d1_m",
    0.12,
    0.0,
    2.0,
    "m",
    "Height of the neck's pitch axis above its yaw base (D-H d1 of eq. 1), m; believed as "
    "`head.baseline_m` is.",
)
NECK_A2 = Setting(
    "neck_a2_m",
    0.09,
    0.0,
    1.0,
    "m",
    "Height of H above the pitch axis (D-H a2 of eq. 1), m; believed as `head.baseline_m` is.",
)
ENCODER_RESOLUTION = Setting(
    "encoder_resolution_rad",
    ENCODER_RESOLUTION_RAD,
    0.0,
    0.01,
    "rad",
    "One encoder count of every joint, rad.",
    lo_open=True,
)
BACKLASH = Setting(
    "backlash_rad",
    0.0,
    0.0,
    0.01,
    "rad",
    "Backlash: every joint settles half of it short, on the side it came from, rad.",
)
COUNT_ERROR = Flag(
    "count_error",
    False,
    "If true, the true angle lies anywhere within the encoder count read (seeded).",
)
#: The head's declared numbers.
HEAD_SETTINGS = (BASELINE, NECK_D1, NECK_A2, ENCODER_RESOLUTION, BACKLASH)
#: What the head believes of itself (:class:`HeadBelief`), within the true head's ranges.
BELIEVED_BASELINE = replace(
    BASELINE, meaning="Believed baseline, m (default: the preset's belief, else the design's)."
)
BELIEVED_D1 = replace(NECK_D1, meaning="Believed neck d1, m (default as `belief.baseline_m`).")
BELIEVED_A2 = replace(NECK_A2, meaning="Believed neck a2, m (default as `belief.baseline_m`).")
BELIEVED_SIDE_OFFSET = replace(
    SIDE_OFFSET,
    default=(0.0, 0.0),
    count=2,
    meaning="Believed line-of-sight (side) offset per camera, m, until calibrated.",
)
#: The believed quantities a scenario's ``[belief]`` sets, in the order it reads them.
BELIEF_SETTINGS = (BELIEVED_BASELINE, BELIEVED_D1, BELIEVED_A2, BELIEVED_SIDE_OFFSET)


@dataclass(frozen=True)
class HeadBelief:
    """What the head believes about its own geometry (its design drawings), m.

    The estimators and procedures use this, never the true :class:`HeadSettings`.
    Defaults are the nominal design: D = 150 mm, d1 = 0.12 m, a2 = 0.09 m, each
    optical centre on its eye's yaw axis.  ``nodal_offset_m``/``side_offset_m``:
    per camera (Ca1, Ca2), forward along the optical axis and along the camera's
    x; the estimators use the side offset as each line of sight's offset until
    a calibration measures it (the forward one needs the intrinsics to act).
    """

    baseline_m: float = BASELINE.fixed_default
    neck_d1_m: float = NECK_D1.fixed_default
    neck_a2_m: float = NECK_A2.fixed_default
    nodal_offset_m: tuple[float, float] = (0.0, 0.0)
    side_offset_m: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        for setting in (BASELINE, NECK_D1, NECK_A2):  # believed within the true head's range
            problem = setting.check(getattr(self, setting.name))
            _check(problem is None, f"belief.{problem}")
        for setting in (NODAL_OFFSET, SIDE_OFFSET):  # per camera, within the camera's range
            name, lo, hi = setting.name, setting.lo, setting.hi
            pair = getattr(self, name)
            _check(
                isinstance(pair, tuple) and len(pair) == 2,
                f"belief.{name} must be a pair (Ca1, Ca2) of numbers, got {pair!r}",
            )
            for value in pair:
                _finite(f"belief.{name}", value)
                _check(
                    lo <= value <= hi,
                    f"belief.{name} must be within [{lo:g}, {hi:g}] m, got {value}",
                )


#: The believed quantities, in :class:`HeadBelief`'s order.
BELIEF_KEYS = ("baseline_m", "neck_d1_m", "neck_a2_m", "nodal_offset_m", "side_offset_m")
#: Where a believed quantity came from (:func:`belief_sources`): the head's design; the
#: preset's own belief; the scenario's ``[belief]``; a :class:`HeadBelief` given in Python;
#: or the true head's value, which the scenario changed and the belief followed.
BELIEF_SOURCES = ("design", "preset", "file", "given", "truth")
_LENGTHS = ("baseline_m", "neck_d1_m", "neck_a2_m")


def belief_sources(
    settings: HeadSettings,
    design: HeadSettings | None = None,
    *,
    given: Collection[str] = (),
    source: str = "given",
) -> dict[str, str]:
    """Where each believed quantity of ``settings`` came from (:data:`BELIEF_SOURCES`).

    ``design``: the head as its preset builds it before the scenario changes it
    (None: only ``settings`` is known); ``given``: the keys that ``source``
    ("file" or "given") set.  A quantity not given comes from the preset's own
    belief when ``design`` has one; else, with no belief at all, it follows the
    truth: "design" where the truth is the design's, "truth" where it is not.
    """
    out: dict[str, str] = {}
    for key in BELIEF_KEYS:
        if key in given:
            out[key] = source
        elif design is not None and design.belief is not None:
            out[key] = "preset"
        elif settings.belief is not None and design is None:
            out[key] = source
        elif settings.belief is not None or key not in _LENGTHS:
            out[key] = "design"  # a [belief] table's missing keys, and the offsets: on axis
        elif design is not None and getattr(settings, key) == getattr(design, key):
            out[key] = "design"
        else:
            out[key] = "truth"
    return out


@dataclass(frozen=True)
class HeadSettings:
    """The true head: baseline, neck D-H parameters, encoder, joints and the two cameras.

    ``belief``: what the head believes of its geometry; None means it was built
    as designed (the belief equals this truth's baseline and neck, with the
    optical centres believed on their axes).  ``backlash_rad``: play of every
    joint's gearing, rad: a joint settles ``backlash_rad / 2`` short of its
    command, on the side it came from (typically 1e-4-1e-3 rad for harmonic
    and spur gears).  ``count_error``: the true angle lies anywhere within the
    encoder count that is read (uniform, seeded per joint and count), not on it.
    """

    baseline_m: float = BASELINE.fixed_default
    neck_d1_m: float = NECK_D1.fixed_default
    neck_a2_m: float = NECK_A2.fixed_default
    encoder_resolution_rad: float = ENCODER_RESOLUTION.fixed_default
    cameras: tuple[CameraSettings, CameraSettings] = field(
        default_factory=lambda: (CameraSettings(), CameraSettings())
    )
    seed: int = 0
    belief: HeadBelief | None = None
    backlash_rad: float = BACKLASH.fixed_default
    count_error: bool = False
    render: RenderFidelity = field(default_factory=RenderFidelity)
    #: Which head: its MJCF and mapping (:mod:`headsim.sim.heads`); the lengths above are
    #: its true ones, and on another head than the paper's they start from its design.
    head: HeadModel = PAPER

    def __post_init__(self) -> None:
        _check(isinstance(self.head, HeadModel), "head must be a headsim.sim.heads.HeadModel")
        for setting in HEAD_SETTINGS:
            problem = setting.check(getattr(self, setting.name))
            _check(problem is None, str(problem))
        _check(
            isinstance(self.count_error, bool),
            f"count_error must be true or false, got {self.count_error!r}",
        )
        _check(
            self.belief is None or isinstance(self.belief, HeadBelief),
            "belief must be a HeadBelief or None",
        )
        _check(
            isinstance(self.cameras, tuple)
            and len(self.cameras) == 2
            and all(isinstance(c, CameraSettings) for c in self.cameras),
            "cameras must be a pair of CameraSettings (Ca1, Ca2)",
        )
        _check(
            isinstance(self.seed, int) and self.seed >= 0,
            f"seed must be a non-negative integer, got {self.seed!r}",
        )

    @property
    def believed(self) -> HeadBelief:
        """The head's belief: ``belief``, or the as-designed one (see the class docstring)."""
        if self.belief is not None:
            return self.belief
        return HeadBelief(
            baseline_m=self.baseline_m, neck_d1_m=self.neck_d1_m, neck_a2_m=self.neck_a2_m
        )

    @property
    def joint_errors(self) -> bool:
        """Whether true joint angles differ from the commanded counts (backlash or count error)."""
        return self.backlash_rad > 0.0 or self.count_error


def settings_record(settings: HeadSettings) -> dict[str, Any]:
    """The settings as results.json and snapshots record them: the head model only when
    it is not the paper's (whose records predate the choice of head)."""
    record = asdict(settings)
    for camera in record["cameras"]:
        if not camera["extra"]:
            del camera["extra"]  # the layout of every record made before imperfection modules
    head = record.pop("head")
    if not settings.head.is_paper:
        record["head"] = {**head, "path": _model_path(settings.head.path)}
    return record


def _said(meaning: str) -> str:
    """A declaration's meaning as a reference cell says it: no closing full stop."""
    return meaning.removesuffix(".")


def record_meanings() -> dict[str, str]:
    """What each key of :func:`settings_record`'s table means (paths relative to it, as
    :func:`headsim.codec.describe` lists a table's parts), read from the declarations
    above and the imperfections': the results reference's ``settings`` rows."""
    own = {s.name: s for s in CAMERA_SETTINGS}
    camera = {
        f"cameras[].{f.name}": _said((own.get(f.name) or imperfections.setting(f.name)).meaning)
        for f in fields(CameraSettings)
        if f.name != "extra"
    }
    camera["cameras[].extra"] = (
        "the settings of imperfections registered beyond the fields above, as (name, value) "
        "pairs (absent while there are none)"
    )
    render = {f"render.{s.name.removeprefix('render_')}": _said(s.meaning) for s in RENDER_SETTINGS}
    head = {
        "head.name": "its name: a shipped head's, or the MJCF file's stem",
        "head.path": "its MJCF file: `models/NAME.xml` for a shipped head (the same on every "
        "checkout), a user's file by its path",
        "head.mapping": "the names headsim uses in it (the scenario's `[head.mapping]`: "
        f"{', '.join(f'`{f.name}`' for f in fields(HeadMapping))}; `null`: none)",
    }
    declared = {s.name: _said(s.meaning) for s in (*HEAD_SETTINGS, COUNT_ERROR)}
    undeclared = {  # the record's tables, and the fields no scenario key sets
        "cameras": ("each camera's settings, Ca1's then Ca2's", camera),
        "seed": ("the seed of the head's own draws", {}),
        "belief": (
            "what the head was told it is, as given (`null`: the truth)",
            {f"belief.{key}": meaning for key, meaning in belief_meanings().items()},
        ),
        "render": ("the rendering fidelity", render),
        "head": ("the head, only when it is not the paper's (absent: the paper's head)", head),
    }
    out: dict[str, str] = {}
    for f in fields(HeadSettings):
        if f.name in declared:
            out[f.name] = declared[f.name]
        else:
            out[f.name], parts = undeclared[f.name]
            out.update(parts)
    return out


def belief_meanings() -> dict[str, str]:
    """What each key of a record of :class:`HeadBelief` means, from the declarations of
    the believed quantities (paths relative to it)."""
    declared = {s.name: _said(s.meaning) for s in BELIEF_SETTINGS}
    declared["nodal_offset_m"] = (
        "Believed nodal offset per camera, m (recorded; no estimate uses it, since it acts "
        "only through the goal column's angle off the optical axis)"
    )
    return {key: declared[key] for key in BELIEF_KEYS}


def _model_path(path: Path | None) -> str:
    """A head's MJCF file as records give it: a shipped one as ``models/NAME.xml`` (the
    same on every checkout and install), a user's as its path."""
    if path is not None and path.resolve().is_relative_to(MODELS_DIR.resolve()):
        return f"models/{path.resolve().relative_to(MODELS_DIR.resolve()).as_posix()}"
    return str(path)


def ideal_head(**overrides: object) -> HeadSettings:
    """Ideal pinhole cameras (640 x 480, fovy 45 deg, centred), no offsets."""
    return HeadSettings(**overrides)  # type: ignore[arg-type]


def paper_head(**overrides: object) -> HeadSettings:
    """The paper's head: its cameras' intrinsics, distortion and initial directions.

    The mount yaws are chosen so that each eye's *effective* initial direction
    (mount yaw plus the angle of the image centre's ray off the optical axis,
    what the paper's Sec. V calibration measures) equals the paper's calibrated
    0.0578 and -0.0254 rad.
    """
    cams = []
    for index, (intr, effective) in enumerate(zip(INTRINSICS, INITIAL_DIRECTIONS_RAD, strict=True)):
        cam = CameraSettings(**intr)
        # Ca1's inward direction is its +x, Ca2's its -x (docs/equations.md).
        cams.append(
            replace(cam, mount_yaw_rad=mount_yaw_for_direction(index + 1, effective, cam.pinhole()))
        )
    return HeadSettings(cameras=(cams[0], cams[1]), **overrides)  # type: ignore[arg-type]


def realistic_head(**overrides: object) -> HeadSettings:
    """The paper's head built to a real head's tolerances (:data:`REALISTIC_BUDGET`).

    The head believes the nominal design: D = 150 mm, d1 = 0.12 m, a2 = 0.09 m,
    the optical centres 20 mm in front of their axes and on them sideways.
    """
    b = REALISTIC_BUDGET
    nodal = b["nodal_offset_m"][0]
    side = b["side_offset_m"][0]
    tilt = b["eye_axis_tilt_rad"][0]
    base = paper_head()
    cams = (
        replace(base.cameras[0], nodal_offset_m=nodal, side_offset_m=side, eye_axis_tilt_rad=tilt),
        replace(
            base.cameras[1],
            nodal_offset_m=nodal,
            side_offset_m=-0.5 * side,
            eye_axis_tilt_rad=-0.5 * tilt,
        ),
    )
    values: dict[str, object] = {
        "baseline_m": BASELINE_M + b["baseline_error_m"][0],
        "neck_d1_m": 0.12 + b["neck_error_m"][0],
        "neck_a2_m": 0.09 - b["neck_error_m"][0],
        "cameras": cams,
        "backlash_rad": b["backlash_rad"][0],
        "count_error": True,
        "belief": HeadBelief(nodal_offset_m=(nodal, nodal)),
        "render": FINE_RENDERING,
    }
    values.update(overrides)
    return HeadSettings(**values)  # type: ignore[arg-type]


PRESETS = {"ideal": ideal_head, "paper": paper_head, "realistic": realistic_head}
#: ``[head] preset`` (and a camera's own ``preset``): where every key left out comes from.
PRESET = Choice(
    "preset",
    tuple(PRESETS),
    "ideal",
    "Defaults for the head and both cameras: the ideal head, the paper's, or a realistic one.",
)


def preset(name: str, **overrides: object) -> HeadSettings:
    """Head settings by preset name ("ideal", "paper" or "realistic")."""
    if name not in PRESETS:
        raise SettingsError(f"unknown preset {name!r}; allowed: {', '.join(sorted(PRESETS))}")
    return PRESETS[name](**overrides)
