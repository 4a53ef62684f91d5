"""Settings of the simulated head and its cameras, checked where they enter.

Units: metres, radians, pixels.  Pixel coordinates follow OpenCV: the centre of
pixel (i, j) is at (i, j), so the geometric centre of a W x H image is
((W - 1) / 2, (H - 1) / 2) -- the paper's (320, 240) for 640 x 480.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from headsim.camera_model import PinholeCamera
from headsim.errors import BadInput

#: Largest image side the off-screen buffer is allowed to grow to, px.
MAX_IMAGE_SIDE = 4096
#: Eye-motor encoder resolution of the paper's head, rad (Sec. VI).
PAPER_ENCODER_RESOLUTION = 2 * math.pi / 25600
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


@dataclass(frozen=True)
class CameraSettings:
    """One eye camera: image size, pinhole intrinsics, lens and mount.

    ``cx``/``cy`` default to the image centre.  ``k1``/``k2`` are OpenCV's radial
    coefficients on normalised coordinates.  ``mount_yaw_rad`` is the paper's
    alpha_e (the eye's initial direction, positive inward like the eye angle);
    ``mount_pitch_rad``/``mount_roll_rad`` tilt the camera on its eye (0 in the
    paper).  ``noise_std`` is Gaussian image noise in 8-bit grey levels.
    """

    width: int = 640
    height: int = 480
    kx: float = IDEAL_FOCAL_PX
    ky: float = IDEAL_FOCAL_PX
    cx: float | None = None
    cy: float | None = None
    k1: float = 0.0
    k2: float = 0.0
    mount_yaw_rad: float = 0.0
    mount_pitch_rad: float = 0.0
    mount_roll_rad: float = 0.0
    noise_std: float = 0.0

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            _check(
                isinstance(value, int) and value > 0,
                f"camera {name} must be a positive integer, got {value!r}",
            )
            _check(
                value <= MAX_IMAGE_SIDE,
                f"camera {name} = {value} px is larger than the off-screen buffer allows "
                f"(at most {MAX_IMAGE_SIDE} px)",
            )
        for name in ("kx", "ky"):
            value = getattr(self, name)
            _finite(name, value)
            _check(value > 0, f"focal length {name} must be > 0 px, got {value}")
        for name in ("k1", "k2", "mount_yaw_rad", "mount_pitch_rad", "mount_roll_rad", "noise_std"):
            _finite(name, getattr(self, name))
        for name, size in (("cx", self.width), ("cy", self.height)):
            value = getattr(self, name)
            if value is not None:
                _finite(name, value)
                _check(
                    0 <= value <= size - 1,
                    f"principal point {name} = {value} px lies outside the image [0, {size - 1}]",
                )
        _check(self.noise_std >= 0, f"noise_std must be >= 0, got {self.noise_std}")
        for name in ("mount_yaw_rad", "mount_pitch_rad", "mount_roll_rad"):
            _check(
                abs(getattr(self, name)) < 0.5,
                f"{name} must be within (-0.5, 0.5) rad, got {getattr(self, name)}",
            )

    @property
    def principal(self) -> tuple[float, float]:
        """Principal point (cx, cy), px, OpenCV pixel convention."""
        u, v = self.image_centre
        return (u if self.cx is None else self.cx, v if self.cy is None else self.cy)

    @property
    def image_centre(self) -> tuple[float, float]:
        """Geometric centre of the image, px: ((W - 1) / 2, (H - 1) / 2)."""
        return ((self.width - 1) / 2, (self.height - 1) / 2)

    @property
    def distorted(self) -> bool:
        return self.k1 != 0.0 or self.k2 != 0.0

    def pinhole(self) -> PinholeCamera:
        """The camera's true intrinsics as a :class:`headsim.camera_model.PinholeCamera`."""
        cx, cy = self.principal
        return PinholeCamera(self.width, self.height, self.kx, self.ky, cx, cy, self.k1, self.k2)

    def with_zoom(self, factor: float) -> CameraSettings:
        """The same camera with both focal lengths scaled by ``factor``."""
        _check(factor > 0, f"zoom factor must be > 0, got {factor}")
        return replace(self, kx=self.kx * factor, ky=self.ky * factor)


@dataclass(frozen=True)
class HeadSettings:
    """The head: baseline, neck D-H parameters, encoder and the two cameras."""

    baseline_m: float = 0.150
    neck_d1_m: float = 0.12
    neck_a2_m: float = 0.09
    encoder_resolution_rad: float = PAPER_ENCODER_RESOLUTION
    cameras: tuple[CameraSettings, CameraSettings] = field(
        default_factory=lambda: (CameraSettings(), CameraSettings())
    )
    seed: int = 0

    def __post_init__(self) -> None:
        _finite("baseline_m", self.baseline_m)
        _check(
            0 < self.baseline_m <= 1.0, f"baseline_m must be > 0 and <= 1 m, got {self.baseline_m}"
        )
        _finite("neck_d1_m", self.neck_d1_m)
        _finite("neck_a2_m", self.neck_a2_m)
        _check(
            0 <= self.neck_d1_m <= 2.0, f"neck_d1_m must be within [0, 2] m, got {self.neck_d1_m}"
        )
        _check(
            0 <= self.neck_a2_m <= 1.0, f"neck_a2_m must be within [0, 1] m, got {self.neck_a2_m}"
        )
        _finite("encoder_resolution_rad", self.encoder_resolution_rad)
        _check(
            0 < self.encoder_resolution_rad <= 0.01,
            f"encoder_resolution_rad must be > 0 and <= 0.01 rad, got {self.encoder_resolution_rad}",
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


#: The paper's Zhang intrinsics (Sec. VI, equations.md last table).
PAPER_INTRINSICS = (
    {"kx": 834.83, "ky": 815.42, "cx": 303.8, "cy": 306.3, "k1": -0.38741},
    {"kx": 850.46, "ky": 833.29, "cx": 345.1, "cy": 197.3, "k1": -0.30938},
)
#: The paper's calibrated initial directions alpha_e1, alpha_e2, rad (Sec. VI-B).
PAPER_INITIAL_DIRECTIONS = (0.0578, -0.0254)


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
    from headsim.optics import centre_ray_yaw

    cams = []
    for index, (intr, effective) in enumerate(
        zip(PAPER_INTRINSICS, PAPER_INITIAL_DIRECTIONS, strict=True)
    ):
        cam = CameraSettings(**intr)
        # Ca1's inward direction is its +x, Ca2's its -x (equations.md).
        sign = 1.0 if index == 0 else -1.0
        cams.append(replace(cam, mount_yaw_rad=effective - sign * centre_ray_yaw(cam)))
    return HeadSettings(cameras=(cams[0], cams[1]), **overrides)  # type: ignore[arg-type]


PRESETS = {"ideal": ideal_head, "paper": paper_head}


def preset(name: str, **overrides: object) -> HeadSettings:
    """Head settings by preset name ("ideal" or "paper")."""
    if name not in PRESETS:
        raise SettingsError(f"unknown preset {name!r}; allowed: {', '.join(sorted(PRESETS))}")
    return PRESETS[name](**overrides)
