"""The recording's layout, palette and documents: the default Rerun blueprint (the 3-D
view, both cameras, the traces, one tab per text document), its starting eye, the
recording's id, the colours and marker sizes every logged entity uses, and the markdown
of the scenario's and the calibration's documents."""

from __future__ import annotations

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from headsim.active.calibration_report import CalibrationReport
from headsim.runs import mjcf_rerun
from headsim.scenario.spec import Scenario
from headsim.sim.model import neck_of

#: Half the side of a recorded fovea, px (:mod:`headsim.runs.recording_room`; the
#: template's half side is 20: the fovea is twice its size).
FOVEA_HALF_PX = 40

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
        s = scenario.settings
        head = neck_of(s.head).world_from_head(0.0, 0.0, s.neck_d1_m, s.neck_a2_m)[:3, 3]
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
    if scene.room is not None:  # the objects on the table (the surface targets are drawn later)
        points += [o.pos_world_m for o in scene.room.objects]
    return points


def blueprint(scenario: Scenario | None = None) -> rrb.Blueprint:
    """The default layout: 3-D view, both camera images, servo and joint traces, results.

    Every text document has a view of its own (tabs), so that no view is
    asked to show more than one document.  A room run has its own (:func:`room_blueprint`).
    """
    if scenario is not None and scenario.scene.room is not None:
        return room_blueprint(scenario)
    return _layout(
        scenario,
        "head, scene and targets (W)",
        rrb.Horizontal(
            rrb.TimeSeriesView(origin="/servo", name="servo error, px"),
            rrb.TimeSeriesView(origin="/joints", name="joint encoders, rad"),
            rrb.TimeSeriesView(origin="/measurements", name="measurements"),
        ),
        rrb.Tabs(*text_views(), active_tab=2),
    )


def _layout(scenario: Scenario | None, world: str, *below: rrb.Container) -> rrb.Blueprint:
    """The 3-D view named ``world`` on the left; on the right both cameras above the
    containers ``below`` (the cameras' row 3 shares, each of them 2)."""
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(
                origin="/world",
                name=world,
                eye_controls=eye_controls(scenario),
                defaults=mjcf_rerun.view_defaults(),
            ),
            rrb.Vertical(
                rrb.Horizontal(
                    rrb.Spatial2DView(origin="/world/head/cam1", name="camera 1"),
                    rrb.Spatial2DView(origin="/world/head/cam2", name="camera 2"),
                ),
                *below,
                row_shares=[3, *(2 for _ in below)],
            ),
            column_shares=[2, 3],
        ),
        rrb.TimePanel(timeline="frame", state="collapsed"),
        collapse_panels=True,
    )


def room_blueprint(scenario: Scenario) -> rrb.Blueprint:
    """A room run's layout (:mod:`headsim.runs.recording_room`): the textured room in 3-D
    with the landing rays; both cameras; each eye's fovea beside camera 1's template and
    camera 2's matched patch; the match scores, the match status and the servo error;
    the joints, the measurements and the documents in tabs."""

    side = 2 * FOVEA_HALF_PX + 1
    # The foveal views keep the crop's bounds: a match box outside it does not zoom out.
    bounds = rrb.VisualBounds2D(x_range=[-0.5, side - 0.5], y_range=[-0.5, side - 0.5])

    def fovea(cam: str, name: str) -> rrb.Spatial2DView:
        origin = f"/fovea/{cam}"
        return rrb.Spatial2DView(
            origin=origin,
            contents=[f"{origin}/image", f"{origin}/match"],
            name=name,
            visual_bounds=bounds,
        )

    return _layout(
        scenario,
        "room, head and where the eyes landed (W)",
        rrb.Horizontal(
            fovea("cam1", "fovea 1"),
            rrb.Spatial2DView(origin="/fovea/cam1/template", name="template 1"),
            fovea("cam2", "fovea 2"),
            rrb.Spatial2DView(origin="/fovea/cam2/patch", name="found in 2"),
        ),
        rrb.Horizontal(
            rrb.TimeSeriesView(origin="/correlation", name="match score, ambiguity"),
            rrb.TextLogView(origin="/correlation/status", name="match status"),
            rrb.TimeSeriesView(origin="/servo", name="servo error, px"),
        ),
        rrb.Tabs(
            *text_views(),
            rrb.TimeSeriesView(origin="/measurements", name="measurements"),
            rrb.TimeSeriesView(origin="/joints", name="joint encoders, rad"),
            active_tab=2,
        ),
    )


def recording_id(scenario: Scenario) -> str:
    """Deterministic id: scenario, variant and seed."""
    return f"{scenario.name}{'-fast' if scenario.fast else ''}-seed{scenario.seed}"


def scenario_markdown(scenario: Scenario) -> str:
    """The scenario's document: its description, the cameras and the real head."""
    s = scenario
    rows = "\n".join(
        f"| cam{k + 1} | {c.width}x{c.height} | {c.kx:.2f} | {c.ky:.2f} | "
        f"{c.principal[0]:.1f}, {c.principal[1]:.1f} | {c.k1:.4f} | {c.mount_yaw_rad:.4f} | {c.noise_std:g} |"
        for k, c in enumerate(s.settings.cameras)
    )
    return (
        f"# {s.name}{' (fast)' if s.fast else ''}\n\n{s.description}\n\n"
        f"procedure `{s.experiment.procedure}`, preset `{s.preset}`, seed {s.seed}, "
        f"baseline {s.settings.baseline_m * 1000:g} mm\n\n"
        "| camera | size | kx | ky | principal | k1 | mount yaw | noise |\n"
        "|---|---|---|---|---|---|---|---|\n" + rows + "\n" + _real_head_markdown(scenario)
    )


def _real_head_markdown(scenario: Scenario) -> str:
    """The imperfections beyond the paper and what the head believes."""
    s = scenario.settings
    b = s.believed
    cams = "\n".join(
        f"| cam{k + 1} | {1e3 * c.nodal_offset_m:g} | {1e3 * c.side_offset_m:g} | "
        f"{1e3 * c.eye_axis_tilt_rad:g} | {1e3 * b.nodal_offset_m[k]:g} | {1e3 * b.side_offset_m[k]:g} |"
        for k, c in enumerate(s.cameras)
    )
    return (
        f"\ntruth / belief: baseline {s.baseline_m * 1000:g} / {b.baseline_m * 1000:g} mm, "
        f"neck d1 {s.neck_d1_m * 1000:g} / {b.neck_d1_m * 1000:g} mm, "
        f"a2 {s.neck_a2_m * 1000:g} / {b.neck_a2_m * 1000:g} mm; backlash "
        f"{s.backlash_rad:g} rad; count error {'on' if s.count_error else 'off'}; rendering "
        f"offsamples {s.render.offsamples}, supersample {s.render.supersample}\n\n"
        "| camera | nodal mm | side mm | axis tilt mrad | believed nodal mm | believed side mm |\n"
        "|---|---|---|---|---|---|\n" + cams + "\n"
    )


def calibration_markdown(report: CalibrationReport) -> str:
    """The calibration's document: the initial directions and the extended calibration."""
    if not report.ok:
        return f"# Calibration\n\n{report.status_text}\n"
    alpha_e, truth_e, paper_e = (
        report.alpha_e_rad,
        report.alpha_e_truth_rad,
        report.alpha_e_paper_rad,
    )
    assert alpha_e is not None and truth_e is not None and paper_e is not None
    rows = "\n".join(
        f"| alpha_e{k + 1} | {alpha_e[k]:.5f} | {truth_e[k]:.5f} | {paper_e[k]:.4f} |"
        for k in range(2)
    )
    text = (
        "# Calibration of the initial directions (Sec. V)\n\n"
        f"{report.fixated} of {report.targets} positions fixated, {report.renders.total} renders\n\n"
        "| rad | ours | truth | paper |\n|---|---|---|---|\n" + rows + "\n"
    )
    vertical = report.vertical_reference
    if vertical:
        text += "\n| extended | ours | truth |\n|---|---|---|\n" + "\n".join(
            f"| v{k + 1}0 px | {vertical.v0_px[k]:.2f} | {vertical.v0_truth_px[k]:.2f} |\n"
            f"| kx{k + 1}/ky{k + 1} | {vertical.kx_over_ky[k]:.4f} | {vertical.kx_over_ky_truth[k]:.4f} |"
            for k in range(2)
        )
    return text


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
    "calibration_markdown",
    "eye_controls",
    "recording_id",
    "room_blueprint",
    "scenario_markdown",
    "text_views",
]
