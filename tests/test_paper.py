"""The paper's figures (paper.py): in SI units, as the paper prints them, and consistent."""

from __future__ import annotations

import math

import pytest

from headsim import paper


def test_each_figure_is_the_papers_in_si_units() -> None:
    # As printed: D = 150 mm; 2 pi / 25 600 = 2.45e-4 rad; the side 30 mm, 30.3 mm mean,
    # 0.677 mm std; alpha_e = 0.0578, -0.0254 rad; relative fixation 0.08, 0.0349 rad.
    assert pytest.approx(150.0) == paper.BASELINE_M * 1000
    assert round(paper.ENCODER_RESOLUTION_RAD, 6) == 2.45e-4
    assert pytest.approx(2 * math.pi) == paper.ENCODER_RESOLUTION_RAD * 25600
    assert pytest.approx(30.0) == paper.CHESSBOARD_SQUARE_M * 1000
    assert pytest.approx(30.3) == paper.CHESSBOARD_SIDE_MEAN_M * 1000
    assert pytest.approx(0.677) == paper.CHESSBOARD_SIDE_STD_M * 1000
    assert paper.INITIAL_DIRECTIONS_RAD == (0.0578, -0.0254)
    assert (paper.RELATIVE_ALPHA1_RAD, paper.RELATIVE_ALPHA2_RAD) == (0.08, 0.0349)
    assert paper.RELATIVE_OBJECTS == 6
    assert paper.IMAGE_SIZE_PX == (640, 480)


def test_the_intrinsics_are_plausible_for_the_papers_image() -> None:
    width, height = paper.IMAGE_SIZE_PX
    assert len(paper.INTRINSICS) == 2
    for camera in paper.INTRINSICS:
        assert set(camera) == {"kx", "ky", "cx", "cy", "k1"}
        assert 0 < camera["cx"] < width and 0 < camera["cy"] < height
        assert 1.0 < camera["kx"] / camera["ky"] < 1.05  # the paper's square-ish pixels
        assert -1.0 < camera["k1"] < 0.0  # barrel distortion, as the paper's kc
    # Sec. VI-B: the principal points lie off the image centre, on opposite sides in u.
    (cx1, cx2) = (camera["cx"] for camera in paper.INTRINSICS)
    assert cx1 < width / 2 < cx2


def test_all_lists_every_public_name_and_nothing_else() -> None:
    public = {n for n in vars(paper) if not n.startswith("_") and n.isupper()}
    assert set(paper.__all__) == public | {"Intrinsics"}
    assert all(hasattr(paper, name) for name in paper.__all__)
