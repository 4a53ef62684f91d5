"""Radial lens distortion (OpenCV's k1, k2): the camera renders a pinhole canvas, resampled.

MuJoCo renders an ideal pinhole image.  A distorted camera is rendered on a
larger pinhole *canvas* with the same focal lengths, then resampled with
``cv2.remap`` so that output pixel (u, v) shows the scene point whose distorted
projection is (u, v).  Radial model (OpenCV, k1, k2 only) on normalised
coordinates: x_d = x (1 + k1 r^2 + k2 r^4).  Pixels as in OpenCV (centres at
integer coordinates).  A window of the image samples a rectangle of the canvas
(:meth:`Distortion.source`), and its remap tables are the image's, shifted.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any, Protocol

import cv2
import numpy as np

from headsim.geometry.camera_model import PinholeCamera
from headsim.sim.gl_window import Window
from headsim.sim.imperfections.base import (
    NOTHING,
    Camera,
    Canvas,
    Imperfection,
    Setting,
    Shot,
    register,
)

K1 = Setting(
    "k1", 0.0, -1.0, 1.0, "", "First radial distortion coefficient (OpenCV's).", example=-0.35
)
K2 = Setting(
    "k2", 0.0, -1.0, 1.0, "", "Second radial distortion coefficient (OpenCV's).", example=0.2
)


class Lens(Protocol):
    """What the canvas is made from (:class:`headsim.sim.settings.CameraSettings`)."""

    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def kx(self) -> float: ...
    @property
    def ky(self) -> float: ...
    @property
    def principal(self) -> tuple[float, float]: ...
    def pinhole(self) -> PinholeCamera: ...


@dataclass(frozen=True)
class DistortionCanvas:
    """How to render a distorted camera: the pinhole canvas and the resampling map.

    The canvas has the camera's focal lengths, ``size`` = (width, height) px and
    principal point ``principal`` px; ``map_x``/``map_y`` (H, W float32) give,
    for every output pixel, its source on the canvas (-1 where none exists).
    """

    size: tuple[int, int]
    principal: tuple[float, float]
    map_x: np.ndarray | None
    map_y: np.ndarray | None
    valid_fraction: float

    @property
    def identity(self) -> bool:
        """True for a distortion-free camera: the canvas is the image."""
        return self.map_x is None


@functools.lru_cache(maxsize=16)
def distortion_canvas(camera: Lens, max_side: int, margin_px: int = 3) -> DistortionCanvas:
    """Canvas and remap tables for rendering ``camera`` (computed once per camera and process;
    the tables are shared: read-only)."""
    w, h = camera.width, camera.height
    cx, cy = camera.principal
    if not camera.pinhole().is_distorted:
        return DistortionCanvas((w, h), (cx, cy), None, None, 1.0)
    us, vs = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    xy = camera.pinhole().normalise(np.stack([us, vs], axis=-1), strict=False, tol_px=1e-6)
    valid = np.isfinite(xy).all(axis=-1)
    up = camera.kx * xy[..., 0] + cx
    vp = camera.ky * xy[..., 1] + cy
    # Canvas bounds: everything the valid output pixels need, plus a margin for
    # bilinear sampling, at most max_side on a side.
    u_lo = math.floor(float(up[valid].min())) - margin_px
    u_hi = math.ceil(float(up[valid].max())) + margin_px
    v_lo = math.floor(float(vp[valid].min())) - margin_px
    v_hi = math.ceil(float(vp[valid].max())) + margin_px
    u_lo, u_hi = _clamp_span(u_lo, u_hi, max_side)
    v_lo, v_hi = _clamp_span(v_lo, v_hi, max_side)
    map_x = up - u_lo
    map_y = vp - v_lo
    width_c, height_c = u_hi - u_lo + 1, v_hi - v_lo + 1
    inside = (map_x >= 0) & (map_x <= width_c - 1) & (map_y >= 0) & (map_y <= height_c - 1)
    valid &= inside
    map_x[~valid] = -1.0
    map_y[~valid] = -1.0
    map_x, map_y = map_x.astype(np.float32), map_y.astype(np.float32)
    map_x.flags.writeable = map_y.flags.writeable = False  # shared through the cache
    return DistortionCanvas(
        size=(width_c, height_c),
        principal=(cx - u_lo, cy - v_lo),
        map_x=map_x,
        map_y=map_y,
        valid_fraction=float(valid.mean()),
    )


def _clamp_span(lo: int, hi: int, max_side: int) -> tuple[int, int]:
    if hi - lo + 1 <= max_side:
        return lo, hi
    centre = (lo + hi) // 2
    return centre - max_side // 2, centre - max_side // 2 + max_side - 1


def apply_canvas(canvas_rgb: np.ndarray, canvas: DistortionCanvas) -> np.ndarray:
    """Resample a rendered canvas into the distorted output image (black where no source)."""
    if canvas.map_x is None or canvas.map_y is None:
        return canvas_rgb
    return cv2.remap(
        canvas_rgb,
        canvas.map_x,
        canvas.map_y,
        interpolation=cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_CONSTANT,
        borderValue=(0, 0, 0),
    )


#: Binned canvases by (id of the canvas, binning), with the canvas kept alive.
_BINNED: dict[tuple[int, int], tuple[DistortionCanvas, DistortionCanvas]] = {}


def binned_canvas(
    canvas: DistortionCanvas, binning: int, image_size: tuple[int, int]
) -> DistortionCanvas:
    """``canvas`` for images binned ``binning`` x ``binning`` from a canvas binned alike
    (made once per canvas and binning).

    The remap tables' b x b blocks are averaged (the block centre's sample of a
    smooth map) and moved to the binned canvas's pixels; a block with any pixel
    without source has none.
    """
    key = (id(canvas), binning)
    if key not in _BINNED:
        _BINNED[key] = (canvas, _binned_canvas(canvas, binning, image_size))
    return _BINNED[key][1]


def _binned_canvas(
    canvas: DistortionCanvas, binning: int, image_size: tuple[int, int]
) -> DistortionCanvas:
    width, height = image_size
    size = (width // binning, height // binning)
    width_b = (canvas.size[0] - canvas.size[0] % binning) // binning
    height_b = (canvas.size[1] - canvas.size[1] % binning) // binning
    if canvas.map_x is None or canvas.map_y is None:
        return DistortionCanvas((width_b, height_b), canvas.principal, None, None, 1.0)
    offset = (binning - 1) / 2.0
    invalid = (
        cv2.resize((canvas.map_x < 0).astype(np.float32), size, interpolation=cv2.INTER_AREA) > 0
    )
    map_x = (cv2.resize(canvas.map_x, size, interpolation=cv2.INTER_AREA) - offset) / binning
    map_y = (cv2.resize(canvas.map_y, size, interpolation=cv2.INTER_AREA) - offset) / binning
    invalid |= (map_x < 0) | (map_x > width_b - 1) | (map_y < 0) | (map_y > height_b - 1)
    map_x[invalid] = -1.0
    map_y[invalid] = -1.0
    map_x, map_y = map_x.astype(np.float32), map_y.astype(np.float32)
    map_x.flags.writeable = map_y.flags.writeable = False
    return DistortionCanvas(
        size=(width_b, height_b),
        principal=canvas.principal,
        map_x=map_x,
        map_y=map_y,
        valid_fraction=float(1.0 - invalid.mean()),
    )


def canvas_region(
    map_x: np.ndarray, map_y: np.ndarray, canvas_size: tuple[int, int]
) -> Window | None:
    """The canvas rectangle that bilinear sampling at (map_x, map_y) reads (None: no valid source)."""
    valid = map_x >= 0
    if not valid.any():
        return None
    xs, ys = map_x[valid], map_y[valid]
    x0 = max(math.floor(float(xs.min())) - 1, 0)
    y0 = max(math.floor(float(ys.min())) - 1, 0)
    x1 = min(math.floor(float(xs.max())) + 3, canvas_size[0])
    y1 = min(math.floor(float(ys.max())) + 3, canvas_size[1])
    return Window(x0, y0, x1 - x0, y1 - y0)


class Distortion(Imperfection):
    """The lens: the canvas resampled through the camera's radial distortion."""

    name = "distortion"
    order = 0
    settings = (K1, K2)

    def prepare(self, camera: Camera, canvas: Canvas) -> Any:
        assert isinstance(canvas, DistortionCanvas)
        return canvas

    def active(self, state: Any) -> bool:
        return not state.identity

    def source(self, state: Any, window: Window) -> Window:
        assert state.map_x is not None and state.map_y is not None
        map_x = state.map_x[window.y0 : window.y1, window.x0 : window.x1]
        map_y = state.map_y[window.y0 : window.y1, window.x0 : window.x1]
        region = canvas_region(map_x, map_y, state.size)
        return NOTHING if region is None else region

    def apply(self, image: np.ndarray, state: Any, shot: Shot) -> np.ndarray:
        canvas: DistortionCanvas = state
        if shot.binning > 1:
            return apply_canvas(image, binned_canvas(canvas, shot.binning, shot.full_size))
        window, source = shot.window, shot.source
        if window is None or source is None:
            return apply_canvas(image, canvas)
        assert canvas.map_x is not None and canvas.map_y is not None
        map_x = canvas.map_x[window.y0 : window.y1, window.x0 : window.x1]
        map_y = canvas.map_y[window.y0 : window.y1, window.x0 : window.x1]
        # Shifting float32 maps by whole pixels is exact: the same samples.
        shifted = DistortionCanvas(
            size=(source.width, source.height),
            principal=canvas.principal,
            map_x=np.where(map_x >= 0, map_x - np.float32(source.x0), np.float32(-1)),
            map_y=np.where(map_y >= 0, map_y - np.float32(source.y0), np.float32(-1)),
            valid_fraction=canvas.valid_fraction,
        )
        return apply_canvas(image, shifted)


register(Distortion())
