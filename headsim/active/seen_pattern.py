"""Where the eye servo last saw a pattern (a chessboard): every feature and the box the
whole pattern needs, px in the full frame, kept to look for one feature alone."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from headsim.sim.render import unbinned_px
from headsim.vision.detection import Detection

#: A pattern's feature is looked for alone only after an image motion of at most this
#: many pattern spacings since the pattern was last seen: the gain's linear prediction
#: is then good to well within the 0.3 spacing that tells the feature from its neighbours
#: (a chessboard corner 1,300 steps of eye motion away was predicted a square off).
ALONE_MOTION = 2.0
#: A pattern is looked for in a binned preview only where its spacing stays at least
#: this many pixels there: OpenCV found every chessboard of 14 px squares (the scene's
#: board at 0.85 m binned 2 x 2) and none of 7 px (4 x 4).
PREVIEW_MIN_SPACING_PX = 10.0


@dataclass(frozen=True, eq=False)
class SeenPattern:
    """Every feature (N, 2) px, the spacing px, and the box (left, top, right, bottom) px
    that finding the whole pattern needs, where the last detection put them."""

    features: np.ndarray
    spacing_px: float
    box: np.ndarray

    @classmethod
    def from_whole(cls, detection: Detection) -> SeenPattern | None:
        """From a detection of the whole pattern (None: not one)."""
        if detection.uv is None or detection.pattern_uv is None or detection.extent_px is None:
            return None
        u, v = detection.uv
        left, top, right, bottom = detection.extent_px
        box = np.array([u + left, v + top, u + right, v + bottom])
        return cls(np.array(detection.pattern_uv), detection.pattern_scale_px, box)

    @classmethod
    def from_preview(cls, detection: Detection, binning: int) -> SeenPattern | None:
        """From a detection of the whole pattern in a preview binned ``binning`` x
        ``binning`` (None: not one), in the full frame's pixels: binned pixel i covers
        pixels b i .. b i + b - 1 (:func:`headsim.sim.render.unbinned_px`)."""
        binned = cls.from_whole(detection)
        if binned is None:
            return None
        return cls(
            unbinned_px(binned.features, binning),
            binning * binned.spacing_px,
            unbinned_px(binned.box, binning),
        )

    def found_alone(self, index: int, uv: tuple[float, float]) -> SeenPattern:
        """Moved so that feature ``index``, found alone, is at ``uv``."""
        shift = np.asarray(uv) - self.features[index]
        return SeenPattern(self.features + shift, self.spacing_px, self.box + shift[[0, 1, 0, 1]])

    def extent_from(self, uv: tuple[float, float]) -> tuple[float, float, float, float]:
        """The whole pattern's box from ``uv``, px: (left, top, right, bottom)."""
        left, top, right, bottom = (float(x) for x in self.box)
        return (left - uv[0], top - uv[1], right - uv[0], bottom - uv[1])

    def expects_alone(self, index: int, motion_px: float) -> bool:
        """Whether feature ``index`` may be looked for alone after ``motion_px`` of motion."""
        return (
            0 <= index < len(self.features)
            and self.spacing_px > 0.0
            and abs(motion_px) <= ALONE_MOTION * self.spacing_px
        )


def preview_binning(spacing_px: float, largest: int, image_size: tuple[int, int]) -> int:
    """The largest binning up to ``largest`` (a power of two dividing the image) that keeps
    the pattern's spacing at least :data:`PREVIEW_MIN_SPACING_PX`; 1: none does."""
    width, height = image_size
    b = 1
    while (
        2 * b <= largest
        and width % (2 * b) == 0
        and height % (2 * b) == 0
        and spacing_px / (2 * b) >= PREVIEW_MIN_SPACING_PX
    ):
        b *= 2
    return b


def remembered(
    kept: SeenPattern | None, detection: Detection, found_alone: int | None
) -> SeenPattern | None:
    """What to keep after ``detection`` (FOUND): the pattern it saw whole; the kept one
    moved to it when it is feature ``found_alone`` found alone; else nothing (a blob)."""
    whole = SeenPattern.from_whole(detection)
    if whole is not None:
        return whole
    if found_alone is not None and kept is not None and detection.uv is not None:
        return kept.found_alone(found_alone, detection.uv)
    return None


__all__ = [
    "ALONE_MOTION",
    "PREVIEW_MIN_SPACING_PX",
    "SeenPattern",
    "preview_binning",
    "remembered",
]
