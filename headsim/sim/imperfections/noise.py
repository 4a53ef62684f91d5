"""Gaussian image noise: every image gets its own, seeded by its stream and number.

A window of an image gets the full frame's noise, cropped, drawn for the window's rows
only (:meth:`GaussianNoise.apply`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from headsim.sim.imperfections.base import Camera, Canvas, Imperfection, Setting, Shot, register

NOISE_STD = Setting(
    "noise_std",
    0.0,
    0.0,
    50.0,
    "grey levels",
    "Gaussian image noise, grey levels (seeded by `seed`).",
    example=4.0,
)


#: Random bits per noise value: one byte picks an alias bucket, one decides within it,
#: so every outcome's probability is exact to 2**-16.
_BUCKETS = 256
#: Outcomes whose rounded-Gaussian probability is below this are folded into their neighbours.
_TAIL_PROBABILITY = 2.0**-20
#: Bytes of random bits per draw of the generator (PCG64DXSM: one 64-bit word): each row
#: of a frame's random bits starts on a draw, so that a window's first row is reached by
#: advancing the generator (:func:`_rows`).
_WORD_BYTES = 8


def _rounded_gaussian(std: float) -> tuple[np.ndarray, np.ndarray]:
    """Values k and probabilities P(rint(std * z) = k), z standard normal (tails folded in)."""
    from statistics import NormalDist

    normal = NormalDist()
    k_max = 0
    while 2.0 * (1.0 - normal.cdf((k_max + 0.5) / std)) > _TAIL_PROBABILITY:
        k_max += 1
    values = np.arange(-k_max, k_max + 1)
    edges = [normal.cdf((k + 0.5) / std) for k in range(-k_max - 1, k_max + 1)]
    edges[0], edges[-1] = 0.0, 1.0  # the folded tails
    return values, np.diff(np.array(edges))


@dataclass(frozen=True)
class GaussianNoise:
    """Zero-mean Gaussian image noise of ``std`` grey levels, at about 1 ms per 640x480 frame.

    Adding ``std * z`` and rounding to 8 bits gives an integer offset whose law
    is the rounded Gaussian P(k) = Phi((k + 1/2)/std) - Phi((k - 1/2)/std) (the
    image is integer).  That law is sampled directly with Walker's alias
    method: two random bytes per value, two 8-bit table look-ups and a
    comparison, all in OpenCV; the result is the image plus the offset,
    saturated to [0, 255] in one pass
    (what ``clip(rint(image + std * z))`` gives).  Probabilities are exact to
    2**-16 (each); the outcomes too rare for that (beyond about 4 std, a tail
    of less than 1e-4) are folded into the extreme values.  Noise of image number
    ``frame`` of a stream ``key`` is drawn from its own generator (PCG64DXSM), seeded
    by ``(*key, frame)``: the same for a given seed, camera and image count, and
    independent between images, pixels and colour channels.  A window's rows are
    drawn by advancing the generator to its first row (a jump, not a draw): a window
    costs its rows, not the frame.  Up to 127
    outcomes on each side (std <= 25); larger noise falls back to Box-Muller samples
    (two 32-bit uniforms per value) with the same law.
    """

    std: float
    #: (alias, threshold) per bucket and k_max; None: float samples (std > 25 or no noise).
    tables: tuple[np.ndarray, np.ndarray, int] | None

    @classmethod
    def of(cls, std: float) -> GaussianNoise:
        """Precompute the alias tables for noise of ``std`` grey levels."""
        if std <= 0:
            return cls(0.0, None)
        values, probs = _rounded_gaussian(std)
        if len(values) > _BUCKETS:
            return cls(float(std), None)
        # Probabilities in whole units of 2**-16 (largest remainders), then
        # Vose's alias method on 256 equally likely buckets of 256 units each.
        exact = probs * 65536.0
        units = np.floor(exact).astype(int)
        short = 65536 - int(units.sum())
        units[np.argsort(units - exact)[:short]] += 1
        weight = np.zeros(_BUCKETS, dtype=int)
        weight[: len(values)] = units
        primary = np.arange(_BUCKETS)
        alias = np.arange(_BUCKETS)
        keep = np.full(_BUCKETS, _BUCKETS)
        small = [i for i in range(_BUCKETS) if weight[i] < _BUCKETS]
        large = [i for i in range(_BUCKETS) if weight[i] >= _BUCKETS]
        while small and large:
            s, g = small.pop(), large.pop()
            keep[s], alias[s] = weight[s], g
            weight[g] -= _BUCKETS - weight[s]
            (small if weight[g] < _BUCKETS else large).append(g)
        # A full bucket (256 of 256) keeps its primary whatever the byte: alias to itself.
        alias = np.where(keep >= _BUCKETS, primary, alias)
        threshold = np.minimum(keep, _BUCKETS - 1)
        return cls(
            float(std), (alias.astype(np.uint8), threshold.astype(np.uint8), len(values) // 2)
        )

    def probabilities(self) -> dict[int, float]:
        """The offset law this sampler draws from: value -> probability (exact fractions of 2**-16)."""
        if self.std <= 0:
            return {0: 1.0}
        values, probs = _rounded_gaussian(self.std)
        if self.tables is None:
            return dict(zip(values.tolist(), probs.tolist(), strict=True))
        alias, threshold, k_max = self.tables
        law: dict[int, float] = {}
        for bucket in range(_BUCKETS):
            p_keep = (threshold[bucket] if alias[bucket] != bucket else _BUCKETS) / _BUCKETS
            for outcome, p in ((bucket, p_keep), (int(alias[bucket]), 1.0 - p_keep)):
                if p > 0:
                    value = outcome - k_max
                    law[value] = law.get(value, 0.0) + p / _BUCKETS
        return law

    def apply(
        self,
        image: np.ndarray,
        key: tuple[int, ...],
        frame: int,
        crop: tuple[int, int, int, int] | None = None,
    ) -> np.ndarray:
        """``image`` (8-bit) plus noise image number ``frame`` of stream ``key``.

        ``crop`` = (x0, y0, full width, full height): ``image`` is the window at
        (x0, y0) of a full frame of that size, and gets that part of the full
        frame's noise.
        """
        if self.std <= 0:
            return image
        height, width = image.shape[:2]
        x0, y0, full_w, full_h = (0, 0, width, height) if crop is None else crop
        channels = image.shape[2] if image.ndim == 3 else 1
        values = full_w * channels  # per row of the full frame
        columns = slice(x0 * channels, (x0 + width) * channels)
        flat = np.ascontiguousarray(image).reshape(height, width * channels)
        bits = np.random.PCG64DXSM(np.random.SeedSequence([*key, frame]))
        if self.tables is None:  # a 64-bit word per value
            words = _rows(bits, y0, height, 8 * values).view(np.uint64)[:, columns]
            halves = words.view(np.uint32).reshape(*words.shape, 2).astype(np.float32)
            u1 = (halves[..., 0] + np.float32(1.0)) * np.float32(2.0**-32)  # (0, 1]
            angle = halves[..., 1] * np.float32(2.0 * np.pi * 2.0**-32)
            z = np.sqrt(np.float32(-2.0) * np.log(u1)) * np.cos(angle)
            noisy = flat.astype(np.float32) + np.float32(self.std) * z
            return np.clip(np.rint(noisy), 0, 255).astype(np.uint8).reshape(image.shape)
        alias, threshold, k_max = self.tables
        # Two planes of a byte per value, one after the other: the frame's rows of
        # buckets, then its rows of decisions within them.
        bucket = _rows(bits, y0, height, values)[:, columns]
        within = _rows(bits, full_h - height, height, values)[:, columns]
        # Outcome index: the bucket itself (Vose's primary) or its alias; offset = index - k_max.
        outcome = cv2.LUT(bucket, alias)
        cv2.copyTo(bucket, cv2.compare(within, cv2.LUT(bucket, threshold), cv2.CMP_LT), outcome)
        # One saturating pass: image + outcome - k_max, exact integers in float, to [0, 255].
        noisy = cv2.addWeighted(flat, 1.0, outcome, 1.0, -float(k_max), dtype=cv2.CV_8U)
        return noisy.reshape(image.shape)


def _rows(bits: np.random.PCG64DXSM, skip: int, height: int, row_bytes: int) -> np.ndarray:
    """The next ``height`` rows of ``row_bytes`` random bytes from ``bits``, (height,
    row_bytes) uint8, after jumping over ``skip`` rows (each row starts on a draw)."""
    words = -(-row_bytes // _WORD_BYTES)
    bits.advance(skip * words)
    raw = bits.random_raw(height * words).view(np.uint8).reshape(height, words * _WORD_BYTES)
    return raw[:, :row_bytes]


class Noise(Imperfection):
    """Zero-mean Gaussian noise of ``noise_std`` grey levels on every image."""

    name = "noise"
    order = 50
    settings = (NOISE_STD,)

    def prepare(self, camera: Camera, canvas: Canvas) -> Any:
        return GaussianNoise.of(camera.value(NOISE_STD.name))

    def active(self, state: Any) -> bool:
        return bool(state.std > 0)

    def apply(self, image: np.ndarray, state: Any, shot: Shot) -> np.ndarray:
        window = shot.window
        crop = None if window is None else (window.x0, window.y0, *shot.full_size)
        return state.apply(image, shot.key, shot.frame, crop=crop)


register(Noise())
