"""Every number taken from the paper, each with its section.

De Xu, You Fu Li, Min Tan, Yang Shen, "A new active visual system for humanoid
robots" (the paper headsim reproduces).  Units: metres, radians, pixels (OpenCV's:
pixel centres at integer coordinates).  Nothing here is a setting of headsim's
own: the presets, studies and reports read the paper's figures from here.
"""

from __future__ import annotations

import math
from typing import TypedDict


class Intrinsics(TypedDict):
    """One camera's Zhang intrinsics: kx, ky, px; principal point cx, cy, px; radial k1."""

    kx: float
    ky: float
    cx: float
    cy: float
    k1: float


#: Distance between the two cameras' optical centres, m (Sec. VI: "150 mm").
BASELINE_M = 0.150
#: Eye-motor encoder step, rad (Sec. VI: 2 pi / 25 600 = 2.45e-4 rad).
ENCODER_RESOLUTION_RAD = 2 * math.pi / 25600
#: Image size (width, height), px (Sec. VI: 640 x 480, centre (320, 240) used as u0, v0).
IMAGE_SIZE_PX = (640, 480)
#: Calibrated initial directions alpha_e1, alpha_e2, rad (Sec. VI, by the method of Sec. V).
INITIAL_DIRECTIONS_RAD = (0.0578, -0.0254)
#: Zhang intrinsics of Ca1 and Ca2 (Sec. VI-B): focal lengths kx, ky, px (rounded to 0.01
#: as in equations.md), principal point (cx, cy), px, radial distortion k1 (the paper's kc).
INTRINSICS: tuple[Intrinsics, Intrinsics] = (
    {"kx": 834.83, "ky": 815.42, "cx": 303.8, "cy": 306.3, "k1": -0.38741},
    {"kx": 850.46, "ky": 833.29, "cx": 345.1, "cy": 197.3, "k1": -0.30938},
)
#: The chessboard's square, m, and the side the paper measured: mean and standard
#: deviation, m (Sec. VI-A, Fig. 10(b): 30 mm; 30.3 mm mean, 0.677 mm std).
CHESSBOARD_SQUARE_M = 0.030
CHESSBOARD_SIDE_MEAN_M = 0.0303
CHESSBOARD_SIDE_STD_M = 0.000677
#: Relative positioning (Sec. VI-C): the eye angles of the fixated cross point,
#: alpha1, alpha2, rad, and the number of objects placed around it.
RELATIVE_ALPHA1_RAD = 0.08
RELATIVE_ALPHA2_RAD = 0.0349
RELATIVE_OBJECTS = 6

__all__ = [
    "BASELINE_M",
    "CHESSBOARD_SIDE_MEAN_M",
    "CHESSBOARD_SIDE_STD_M",
    "CHESSBOARD_SQUARE_M",
    "ENCODER_RESOLUTION_RAD",
    "IMAGE_SIZE_PX",
    "INITIAL_DIRECTIONS_RAD",
    "INTRINSICS",
    "RELATIVE_ALPHA1_RAD",
    "RELATIVE_ALPHA2_RAD",
    "RELATIVE_OBJECTS",
    "Intrinsics",
]
