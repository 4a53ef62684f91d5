"""The recording's layout and palette: the default Rerun blueprint (the 3-D view, both
cameras, the traces, one tab per text document), its starting eye, the recording's id,
and the colours and marker sizes every logged entity uses."""

from __future__ import annotations

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from headsim.run import mjcf_rerun
from headsim.scenario.spec import Scenario

GREEN = (40, 220, 90)

RED = (235, 60, 50)

WHITE = (235, 235, 235)

ORANGE = (255, 160, 30)

GREY = (150, 150, 150)

#: Target markers are a few mm: drawn in screen points so that they show at any zoom.
UI_RADIUS_SMALL = rr.components.Radius.ui_points(3.0)

UI_RADIUS = rr.components.Radius.ui_points(4.0)

UI_RADIUS_LARGE = rr.components.Radius.ui_points(6.0)


#: The text documents of a recording, each shown by its own view (one per tab).
TEXT_DOCUMENTS = {
    "/results/scenario": "scenario",
    "/results/calibration": "calibration",
    "/results/summary": "summary",
    "/results/measurements": "measurements",
}


def text_views() -> list[rrb.TextDocumentView]:
    """One view per text document; each view's query is its document's path alone."""
    return [
        rrb.TextDocumentView(origin=path, contents="$origin", name=name)
        for path, name in TEXT_DOCUMENTS.items()
    ]


def eye_controls(scenario: Scenario | None = None) -> rrb.EyeControls3D:
    """The 3-D view's starting eye: behind and above the head, looking past it at the targets."""
    head = np.array([0.0, 0.0, 0.21])
    if scenario is not None:
        head = np.array([0.0, 0.0, scenario.settings.neck_d1_m + scenario.settings.neck_a2_m])
    points = [head] + [np.asarray(p, dtype=float) for p in _placements(scenario)]
    targets = np.array(points[1:]) if len(points) > 1 else head + np.array([[0.0, 0.8, 0.0]])
    reach = float(np.max(np.linalg.norm(targets - head, axis=1)))
    look_target = head + 0.6 * (targets.mean(axis=0) - head)
    position = head + reach * np.array([0.35, -0.95, 0.75])
    return rrb.EyeControls3D(
        kind=rrb.Eye3DKind.Orbital,
        position=position,
        look_target=look_target,
        eye_up=[0.0, 0.0, 1.0],
    )


def _placements(scenario: Scenario | None) -> list[tuple[float, float, float]]:
    """World positions of what the scenario places (targets, boards, objects, waypoints), m."""
    if scenario is None:
        return []
    scene = scenario.scene
    points = [t.position_world_m for t in (*scene.targets, *scene.objects)]
    points += [p.position_world_m for p in (scene.chessboard, scene.blocks) if p is not None]
    if scene.moving is not None:
        points += list(scene.moving.waypoints_world_m)
    return points


def blueprint(scenario: Scenario | None = None) -> rrb.Blueprint:
    """The default layout: 3-D view, both camera images, servo and joint traces, results.

    Every text document has a view of its own (tabs), so that no view is
    asked to show more than one document.
    """
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(
                origin="/world",
                name="head, scene and targets (W)",
                eye_controls=eye_controls(scenario),
                defaults=mjcf_rerun.view_defaults(),
            ),
            rrb.Vertical(
                rrb.Horizontal(
                    rrb.Spatial2DView(origin="/world/head/cam1", name="camera 1"),
                    rrb.Spatial2DView(origin="/world/head/cam2", name="camera 2"),
                ),
                rrb.Horizontal(
                    rrb.TimeSeriesView(origin="/servo", name="servo error, px"),
                    rrb.TimeSeriesView(origin="/joints", name="joint encoders, rad"),
                    rrb.TimeSeriesView(origin="/measurements", name="measurements"),
                ),
                rrb.Tabs(*text_views(), active_tab=2),
                row_shares=[3, 2, 2],
            ),
            column_shares=[2, 3],
        ),
        rrb.TimePanel(timeline="frame", state="collapsed"),
        collapse_panels=True,
    )


def recording_id(scenario: Scenario) -> str:
    """Deterministic id: scenario, variant and seed."""
    return f"{scenario.name}{'-fast' if scenario.fast else ''}-seed{scenario.seed}"


__all__ = [
    "GREEN",
    "GREY",
    "ORANGE",
    "RED",
    "TEXT_DOCUMENTS",
    "UI_RADIUS",
    "UI_RADIUS_LARGE",
    "UI_RADIUS_SMALL",
    "WHITE",
    "blueprint",
    "eye_controls",
    "recording_id",
    "text_views",
]
