"""The viewer's judge on real and exactly drawn screenshots (no browser needed).

A real screenshot of Rerun 0.41's web viewer with an error panel must fail;
a screenshot drawn here with each view's content in its region must pass, and
lose exactly the verdict of a view that is blanked.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from tests.run.viewer.judge import WINDOW, judge, judge_room, room_view_regions, view_regions

DATA = Path(__file__).resolve().parents[1] / "data"


def drawn_screenshot() -> np.ndarray:
    """A 1280 x 800 RGB page with every view of the default layout drawn."""
    image = np.full((WINDOW[1], WINDOW[0], 3), 255, np.uint8)
    regions = view_regions()
    x0, y0, x1, y1 = regions["3d"]
    image[y0:y1, x0:x1] = (71, 71, 76)  # the table
    image[y0 + 20 : y0 + 80, x0 + 20 : x0 + 80] = (160, 160, 160)  # a grey body
    image[y0 + 100 : y0 + 104, x0 + 20 : x0 + 200] = (255, 160, 30)  # an optical axis
    rng = np.random.default_rng(0)
    for camera in ("camera 1", "camera 2"):
        x0, y0, x1, y1 = regions[camera]
        image[y0:y1, x0:x1] = rng.integers(0, 200, (y1 - y0, x1 - x0, 3), dtype=np.uint8)
    for plot in ("servo plot", "joints plot", "measurements plot"):
        x0, y0, x1, y1 = regions[plot]
        image[(y0 + y1) // 2 : (y0 + y1) // 2 + 3, x0:x1] = (230, 40, 40)  # a red line
    x0, y0, x1, y1 = regions["results"]
    image[y0 + 10 : y0 + 14, x0 + 10 : x0 + 300] = (20, 20, 20)  # a line of text
    return image


def test_regions_lie_inside_the_window_and_do_not_overlap() -> None:
    regions = view_regions()
    assert len(regions) == 7
    boxes = list(regions.values())
    for x0, y0, x1, y1 in boxes:
        assert 0 <= x0 < x1 <= WINDOW[0] and 0 <= y0 < y1 <= WINDOW[1]
    for i, (ax0, ay0, ax1, ay1) in enumerate(boxes):
        for bx0, by0, bx1, by1 in boxes[i + 1 :]:
            assert ax1 <= bx0 or bx1 <= ax0 or ay1 <= by0 or by1 <= ay0


def test_a_drawn_page_passes() -> None:
    verdict = judge(drawn_screenshot())
    assert verdict.ok, verdict.problems
    assert verdict.figures["error_panel_px"] == 0


@pytest.mark.parametrize(
    ("view", "problem"),
    [
        ("camera 2", "camera 2 is empty"),
        ("joints plot", "the joints plot is empty"),
        ("results", "no results text"),
    ],
)
def test_a_blank_view_is_the_only_problem(view: str, problem: str) -> None:
    image = drawn_screenshot()
    x0, y0, x1, y1 = view_regions()[view]
    image[y0:y1, x0:x1] = 255
    problems = judge(image).problems
    assert any(problem in p for p in problems), problems
    assert all(view in p or problem in p for p in problems), problems


def test_the_judge_sees_an_error_panel_and_empty_views() -> None:
    # A real screenshot of Rerun 0.41's web viewer: one TextDocumentView over three
    # documents (the layout before issue 16) beside a good one.
    image = cv2.cvtColor(cv2.imread(str(DATA / "viewer_error_panel.png")), cv2.COLOR_BGR2RGB)
    verdict = judge(image)
    assert not verdict.ok
    assert verdict.figures["error_panel_px"] > 10_000
    assert any("error panel" in p for p in verdict.problems)
    assert any("head's bodies" in p for p in verdict.problems)
    assert any("camera 1" in p for p in verdict.problems)
    # A blank page is not a drawn viewer either.
    blank = np.full((*WINDOW[::-1], 3), 255, np.uint8)
    assert len(judge(blank).problems) >= 8


ROOM_SHOT = Path(__file__).resolve().parents[2] / "docs" / "recording-room.png"


def test_the_room_judge_passes_the_room_screenshot_and_fails_a_blanked_fovea() -> None:
    image = cv2.cvtColor(cv2.imread(str(ROOM_SHOT)), cv2.COLOR_BGR2RGB)
    assert judge_room(image).ok, judge_room(image).problems
    for view in ("fovea 1", "fovea 2", "template 1", "patch 2"):
        blank = image.copy()
        x0, y0, x1, y1 = room_view_regions()[view]
        blank[y0:y1, x0:x1] = 255  # the empty view's background
        problems = judge_room(blank).problems
        assert problems and all(view in p for p in problems), (view, problems)


def test_the_room_judge_fails_a_room_drawn_in_flat_colours() -> None:
    image = cv2.cvtColor(cv2.imread(str(ROOM_SHOT)), cv2.COLOR_BGR2RGB)
    x0, y0, x1, y1 = room_view_regions()["3d"]
    # Each texture replaced by its mean colour: a coarse blur keeps the shapes, not the detail.
    image[y0:y1, x0:x1] = cv2.blur(image[y0:y1, x0:x1], (25, 25))
    problems = judge_room(image).problems
    assert len(problems) == 1 and "textures" in problems[0], problems
