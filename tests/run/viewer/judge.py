"""Judging a screenshot of Rerun's web viewer by the pixels of each view, px.

The viewer draws into a canvas, so its text is not in the DOM: what it
shows is judged by pixel statistics of each view's region of the default
layout (:func:`view_regions`, :func:`judge`).  Pure image arithmetic on an
RGB uint8 screenshot of :data:`WINDOW`'s size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Browser window, px (the screenshot's size).
WINDOW = (1280, 800)


def drawn(image: np.ndarray) -> bool:
    """Whether the page shows more than a blank or loading screen."""
    return float(image.std()) > 10.0


#: Rerun's error panel: its pink background (sRGB), seen in a view whose query returns
#: several text documents ("Can only show one text document at a time").
ERROR_PANEL_RGB = (253, 230, 238)


#: The viewer's top bar and collapsed time panel, px (Rerun 0.41 web viewer).
TOP_BAR_PX = 37


TIME_PANEL_PX = 30


#: A view's title bar, px; regions below are inside views, clear of titles and borders.
VIEW_TITLE_PX = 30


_MARGIN_PX = 8


Region = tuple[int, int, int, int]  # x0, y0, x1, y1, px


def view_regions(size: tuple[int, int] = WINDOW) -> dict[str, Region]:
    """Each view's drawing area in a screenshot of :func:`headsim.runs.recording_layout.blueprint`.

    The layout's shares: columns 2:3; right column rows 3:2:2 (cameras,
    plots, results), cameras side by side, three plots side by side.
    """
    width, height = size
    top, bottom = TOP_BAR_PX, height - TIME_PANEL_PX
    split = width * 2 // 5
    row = (bottom - top) / 7.0
    rows = (top, top + 3 * row, top + 5 * row, bottom)
    third = (width - split) / 3.0
    boxes = {
        "3d": (0, top, split, bottom),
        "camera 1": (split, rows[0], split + (width - split) / 2, rows[1]),
        "camera 2": (split + (width - split) / 2, rows[0], width, rows[1]),
        "servo plot": (split, rows[1], split + third, rows[2]),
        "joints plot": (split + third, rows[1], split + 2 * third, rows[2]),
        "measurements plot": (split + 2 * third, rows[1], width, rows[2]),
        "results": (split, rows[2], width, bottom),
    }
    return {
        name: (
            int(x0) + _MARGIN_PX,
            int(y0) + VIEW_TITLE_PX,
            int(x1) - _MARGIN_PX,
            int(y1) - _MARGIN_PX,
        )
        for name, (x0, y0, x1, y1) in boxes.items()
    }


@dataclass(frozen=True)
class ViewJudgement:
    """What the pixels of each view say; ``problems`` is empty when all views drew."""

    figures: dict[str, float]
    problems: tuple[str, ...]

    @property
    def ok(self) -> bool:
        return not self.problems


def _near(image: np.ndarray, rgb: tuple[int, int, int], tolerance: int) -> np.ndarray:
    return np.abs(image.astype(np.int16) - np.array(rgb, np.int16)).max(axis=2) <= tolerance


def judge(image: np.ndarray) -> ViewJudgement:
    """Judge a screenshot of the default layout by pixel statistics per view.

    - no error panel anywhere (its pink background);
    - 3-D: the head's grey bodies, the table's colour and the orange optical axes;
    - each camera: an image (not the empty view's white background), with contrast;
    - each plot: coloured lines or points;
    - results: text (dark pixels on white).
    """
    figures: dict[str, float] = {}
    problems: list[str] = []

    def need(name: str, value: float, minimum: float, what: str) -> None:
        figures[name] = round(float(value), 5)
        if value < minimum:
            problems.append(f"{what}: {name} = {value:.4g} < {minimum:g}")

    error_px = int(_near(image, ERROR_PANEL_RGB, 3).sum())
    figures["error_panel_px"] = error_px
    if error_px > 500:
        problems.append(f"an error panel is shown ({error_px} px of its background)")
    regions = view_regions((image.shape[1], image.shape[0]))

    def crop(name: str) -> np.ndarray:
        x0, y0, x1, y1 = regions[name]
        return image[y0:y1, x0:x1]

    view = crop("3d")
    spread = view.max(axis=2).astype(int) - view.min(axis=2)
    value = view.max(axis=2)
    need(
        "3d_grey_body_fraction",
        np.mean((spread < 20) & (value > 100) & (value < 225)),
        0.003,
        "the head's bodies are not drawn",
    )
    need("3d_table_fraction", np.mean(_near(view, (71, 71, 76), 8)), 0.05, "the table is not drawn")
    need("3d_orange_px", _near(view, (255, 160, 30), 60).sum(), 30, "no optical axes")
    for camera in ("camera 1", "camera 2"):
        view = crop(camera)
        need(f"{camera}_image_fraction", np.mean(view.min(axis=2) < 235), 0.6, f"{camera} is empty")
        need(f"{camera}_contrast", view.std(), 8.0, f"{camera} has no image")
    for plot in ("servo plot", "joints plot", "measurements plot"):
        view = crop(plot)
        spread = view.max(axis=2).astype(int) - view.min(axis=2)
        need(f"{plot}_coloured_px", (spread > 60).sum(), 150, f"the {plot} is empty")
    need(
        "results_text_fraction",
        np.mean(crop("results").max(axis=2) < 120),
        0.003,
        "no results text",
    )
    return ViewJudgement(figures, tuple(problems))


def room_view_regions(size: tuple[int, int] = WINDOW) -> dict[str, Region]:
    """Each view's drawing area in a screenshot of
    :func:`headsim.runs.recording_layout.room_blueprint`: columns 2:3; right column rows
    3:2:2:2 (cameras; the four foveal views; plots and the status; tabs)."""
    width, height = size
    top, bottom = TOP_BAR_PX, height - TIME_PANEL_PX
    split = width * 2 // 5
    row = (bottom - top) / 9.0
    rows = (top, top + 3 * row, top + 5 * row)
    quarter = (width - split) / 4.0
    boxes: dict[str, tuple[float, float, float, float]] = {
        "3d": (0, top, split, bottom),
        "camera 1": (split, rows[0], split + (width - split) / 2, rows[1]),
        "camera 2": (split + (width - split) / 2, rows[0], width, rows[1]),
    }
    for k, name in enumerate(("fovea 1", "template 1", "fovea 2", "patch 2")):
        boxes[name] = (split + k * quarter, rows[1], split + (k + 1) * quarter, rows[2])
    return {
        name: (
            int(x0) + _MARGIN_PX,
            int(y0) + VIEW_TITLE_PX,
            int(x1) - _MARGIN_PX,
            int(y1) - _MARGIN_PX,
        )
        for name, (x0, y0, x1, y1) in boxes.items()
    }


def judge_room(image: np.ndarray) -> ViewJudgement:
    """Judge a screenshot of a room run's layout by pixel statistics per view.

    - no error panel anywhere;
    - 3-D: the textured room (fine grey-level detail: the mean absolute difference of
      neighbouring pixels, which a flat-coloured room lacks);
    - each camera and each foveal view (foveas, template, matched patch): an image with
      contrast, not the empty view's background.
    """
    figures: dict[str, float] = {}
    problems: list[str] = []

    def need(name: str, value: float, minimum: float, what: str) -> None:
        figures[name] = round(float(value), 5)
        if value < minimum:
            problems.append(f"{what}: {name} = {value:.4g} < {minimum:g}")

    error_px = int(_near(image, ERROR_PANEL_RGB, 3).sum())
    figures["error_panel_px"] = error_px
    if error_px > 500:
        problems.append(f"an error panel is shown ({error_px} px of its background)")
    regions = room_view_regions((image.shape[1], image.shape[0]))
    for name, (x0, y0, x1, y1) in regions.items():
        view = image[y0:y1, x0:x1].astype(np.int16)
        key = name.replace(" ", "_")
        if name == "3d":
            grey = view.mean(axis=2)
            detail = np.abs(np.diff(grey, axis=1)).mean()
            need("3d_texture_detail", detail, 2.0, "the room's textures are not drawn")
            continue
        need(f"{key}_contrast", view.std(), 8.0, f"{name} shows no image")
        background = np.mean(view.min(axis=2) > 235)
        need(f"{key}_not_background", 1.0 - background, 0.3, f"{name} is empty")
    return ViewJudgement(figures, tuple(problems))
