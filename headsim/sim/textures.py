"""Textures made from a seed: pure numpy, no MuJoCo.

Four classes, as the issue names them: ``pink`` (1/f noise: a natural image's
amplitude spectrum, random phases), ``grating`` (a sinusoid of a given period and
orientation), ``low`` (a smooth gradient with faint noise: little for a correlator to
hold on to) and ``repetitive`` (square-wave stripes or checks of a given period: a
second eye can lock onto the wrong one).  Each is a square (N, N) grey level in
[0, 1]; :func:`to_rgb` tints it and quantises it to 8 bits for a MuJoCo texture.
The tint is kept pale so that no texture passes for an emissive marker's colour.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The texture classes, as ``texture = ...`` names them.
TEXTURE_KINDS = ("pink", "grating", "low", "repetitive")


@dataclass(frozen=True)
class TextureSpec:
    """What to draw: ``kind`` (:data:`TEXTURE_KINDS`), ``seed``, side ``size_px``;
    ``period_px`` and ``orientation_rad`` (0: stripes vary along the image's columns)
    for gratings and repetitive patterns; ``checks``: a repetitive pattern of checks,
    not stripes; ``contrast``: the grey range, 0..1 (about the mean 0.5)."""

    kind: str
    seed: int = 0
    size_px: int = 256
    period_px: float = 16.0
    orientation_rad: float = 0.0
    checks: bool = False
    contrast: float = 0.8

    def __post_init__(self) -> None:
        if self.kind not in TEXTURE_KINDS:
            raise ValueError(f"unknown texture {self.kind!r}; allowed: {', '.join(TEXTURE_KINDS)}")
        if self.size_px < 8 or self.size_px > 2048:
            raise ValueError(f"texture size_px must be 8..2048, got {self.size_px}")
        if not 2.0 <= self.period_px <= self.size_px:
            raise ValueError(f"texture period_px must be 2..size_px, got {self.period_px}")
        if not 0.0 < self.contrast <= 1.0:
            raise ValueError(f"texture contrast must be in (0, 1], got {self.contrast}")


def pink_noise(size_px: int, rng: np.random.Generator, exponent: float = 1.0) -> np.ndarray:
    """(N, N) noise whose amplitude spectrum is exactly ``1 / f**exponent`` (random phases,
    zero mean, unit standard deviation); periodic, so it tiles without seams."""
    f = np.hypot(np.fft.fftfreq(size_px)[:, None], np.fft.fftfreq(size_px)[None, :])
    amplitude = np.zeros_like(f)
    amplitude[f > 0] = f[f > 0] ** -exponent
    # The phases of real white noise: Hermitian, so the field is real with exactly
    # this amplitude in every bin.
    phase = np.angle(np.fft.fft2(rng.standard_normal((size_px, size_px))))
    field = np.fft.ifft2(amplitude * np.exp(1j * phase)).real
    return (field - field.mean()) / field.std()


def grating(size_px: int, period_px: float, orientation_rad: float, phase_rad: float) -> np.ndarray:
    """(N, N) sinusoid in [-1, 1]: period ``period_px`` along the direction
    (cos o, sin o) in (column, row) pixels."""
    rows, cols = np.mgrid[0:size_px, 0:size_px].astype(float)
    along = cols * np.cos(orientation_rad) + rows * np.sin(orientation_rad)
    return np.asarray(np.cos(2.0 * np.pi * along / period_px + phase_rad))


def texture_grey(spec: TextureSpec) -> np.ndarray:
    """``spec``'s texture, (N, N) grey levels in [0, 1], the same for the same spec."""
    rng = np.random.default_rng([spec.seed, TEXTURE_KINDS.index(spec.kind)])
    n = spec.size_px
    if spec.kind == "pink":
        field = pink_noise(n, rng)
        # An affine map of the whole range (no clipping): the spectrum keeps its slope.
        middle = (field.max() + field.min()) / 2
        return 0.5 + spec.contrast * (field - middle) / float(np.ptp(field))
    if spec.kind == "grating":
        wave = grating(n, spec.period_px, spec.orientation_rad, rng.uniform(0, 2 * np.pi))
        return 0.5 + 0.5 * spec.contrast * wave
    if spec.kind == "low":
        rows, cols = np.mgrid[0:n, 0:n] / (n - 1)
        angle = rng.uniform(0, 2 * np.pi)
        ramp = np.cos(angle) * cols + np.sin(angle) * rows
        ramp = (ramp - ramp.min()) / max(float(np.ptp(ramp)), 1e-12) - 0.5
        # A gentle ramp and faint fine noise, about one grey level of 255: no more
        # than a camera's own noise.
        faint = 0.005 * rng.standard_normal((n, n))
        return np.clip(0.5 + spec.contrast * (0.25 * ramp + faint), 0.0, 1.0)
    square = _square(n, spec.period_px, spec.orientation_rad)
    if spec.checks:
        square = square * _square(n, spec.period_px, spec.orientation_rad + np.pi / 2)
    return 0.5 + 0.5 * spec.contrast * square


def _square(size_px: int, period_px: float, orientation_rad: float) -> np.ndarray:
    """(N, N) square wave of +-1: +1 over the first half of each period along the
    direction (cos o, sin o) in (column, row) pixels."""
    rows, cols = np.mgrid[0:size_px, 0:size_px].astype(float)
    along = cols * np.cos(orientation_rad) + rows * np.sin(orientation_rad)
    # A hair over: a pixel on a half-period edge (up to rounding) starts the next half.
    half = np.floor(2.0 * along / period_px + 1e-9)
    return np.where(half % 2 == 0, 1.0, -1.0)


def to_rgb(grey: np.ndarray, tint: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> np.ndarray:
    """(N, N, 3) uint8: ``grey`` (0..1) times ``tint`` (each 0..1)."""
    rgb = np.clip(grey, 0.0, 1.0)[..., None] * np.asarray(tint, dtype=float)[None, None, :]
    return np.asarray(np.round(255.0 * rgb), dtype=np.uint8)


def tint_of(seed: int) -> tuple[float, float, float]:
    """A pale colour from ``seed``: each channel 0.7..1, so no texture is a marker's hue."""
    values = np.random.default_rng([seed, 7]).uniform(0.7, 1.0, 3)
    return (float(values[0]), float(values[1]), float(values[2]))


def spectrum_slope(image: np.ndarray, band: tuple[float, float] = (0.02, 0.25)) -> float:
    """The log-log slope of a square image's amplitude spectrum against frequency over
    ``band`` (cycles per pixel), fitted over every frequency bin in it: -1 for 1/f noise."""
    n = image.shape[0]
    spectrum = np.abs(np.fft.fft2(image - image.mean()))
    f = np.hypot(np.fft.fftfreq(n)[:, None], np.fft.fftfreq(n)[None, :])
    keep = (f >= band[0]) & (f <= band[1])
    return float(np.polyfit(np.log(f[keep]), np.log(spectrum[keep]), 1)[0])


__all__ = [
    "TEXTURE_KINDS",
    "TextureSpec",
    "grating",
    "pink_noise",
    "spectrum_slope",
    "texture_grey",
    "tint_of",
    "to_rgb",
]
