"""The zoom fixed points procedure: each camera's principal point as the point a zoom
leaves in place, from chessboard images at the head's focal lengths and at ``zoom``
times them (:func:`headsim.active.principal.principal_points_by_zoom`).  Only pixels
enter the fit; each fixed point is reported beside the simulator's principal point.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from headsim.active.events import PhaseStarted
from headsim.active.measurement import HeadKnowledge
from headsim.active.principal import (
    PROBE_ZOOM,
    PrincipalPointError,
    PrincipalPointRun,
    principal_points_by_zoom,
    zoomed,
)
from headsim.codec import declared, doc
from headsim.procedures.contract import Procedure, register
from headsim.runs.context import head
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.table import format_table
from headsim.scenario.spec import CalibrationSpec, Scenario
from headsim.scenario.tables import Table
from headsim.sim import names
from headsim.sim.declared import Section, Setting

if TYPE_CHECKING:
    from headsim.runs.recording import Recorder


@dataclass(frozen=True)
class ZoomSpec:
    """``[experiment.zoom_fixed_points]``: the focal length ratio, the board poses, and
    the seed of their draws (None: the scenario's seed)."""

    zoom: float = PROBE_ZOOM
    poses: int = 2
    board_seed: int | None = None


@declared
class ZoomFixedPoints:
    """Each camera's zoom fixed point beside the truth, by camera (``run``: the fits
    themselves)."""

    zoom: float = doc("the focal length ratio of the second images")
    views: int = doc("board poses whose corners were found at both focal lengths")
    renders: int = doc("renders of the board at both focal lengths")
    fixed_point_px: tuple[tuple[float, float], ...] = doc("each camera's fixed point (u, v), px")
    truth_px: tuple[tuple[float, float], ...] = doc("each camera's principal point (cx, cy), px")
    error_px: np.ndarray = doc("each camera's fixed point minus its principal point, px")
    std_px: tuple[np.ndarray, ...] = doc("each camera's standard errors of (u, v), px")
    scale: tuple[float, ...] = doc("each camera's fitted scale f' / f")
    residual_rms_px: tuple[float, ...] = doc(
        "each camera's RMS distance of the zoomed corners from the fit, px"
    )
    points: tuple[int, ...] = doc("each camera's matched corners")
    run: PrincipalPointRun = doc("", skip=True)

    @classmethod
    def of(cls, run: PrincipalPointRun) -> ZoomFixedPoints:
        """The fixed points that ``run`` found."""
        return cls(
            zoom=run.zoom,
            views=run.views,
            renders=run.renders,
            fixed_point_px=run.principal_px,
            truth_px=run.truth_px,
            error_px=run.errors_px,
            std_px=tuple(f.std_px for f in run.fits),
            scale=tuple(f.scale for f in run.fits),
            residual_rms_px=tuple(f.residual_rms_px for f in run.fits),
            points=tuple(f.points for f in run.fits),
            run=run,
        )

    def summary_lines(self, paper: bool) -> list[str]:
        """Each camera's fixed point beside the principal point."""
        rows = [
            [cam, f"{u:.2f}, {v:.2f}", f"{tu:.2f}, {tv:.2f}", f"{eu:+.2f}, {ev:+.2f}"]
            for cam, (u, v), (tu, tv), (eu, ev) in zip(
                names.CAMERAS,
                self.run.principal_px,
                self.run.truth_px,
                self.run.errors_px,
                strict=True,
            )
        ]
        return [
            f"Zoom fixed points ({self.run.zoom:g}x, {self.run.views} board views)",
            *format_table(["camera", "fixed point px", "truth px", "error px"], rows),
        ]

    def ok_line(self, measured: int) -> str:
        return f"OK: both fixed points found from {self.run.views} board views"

    def log_rows(self, log: Recorder) -> None:
        """Each camera's fixed point in its image."""
        import rerun as rr  # only when recording: Rerun costs a third of a second to import

        from headsim.runs.recording_layout import GREEN

        for cam, uv in zip(names.CAMERAS, self.run.principal_px, strict=True):
            log.rec.log(
                f"/world/head/{cam}/zoom_fixed_point", rr.Points2D([uv], radii=4.0, colors=[GREEN])
            )


@declared
class NotFound:
    """The fixed points could not be fitted: ``reason`` says why."""

    reason: str = doc("why the fixed points were not found (only then)")

    def failures(self) -> tuple[str, ...]:
        return (f"zoom fixed points: {self.reason}",)

    def summary_lines(self, paper: bool) -> list[str]:
        return [f"Zoom fixed points: not found: {self.reason}"]

    def ok_line(self, measured: int) -> str:
        return "OK"  # never shown: a run without the fixed points fails

    def log_rows(self, log: Recorder) -> None:
        return None


def run_zoom_fixed_points(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], ZoomFixedPoints | NotFound]:
    """The board in ``poses`` seeded poses, rendered at both focal lengths; the fits."""
    spec = scenario.experiment.block
    assert isinstance(spec, ZoomSpec)
    seed = scenario.seed if spec.board_seed is None else spec.board_seed
    twin = replace(scenario, settings=zoomed(scenario.settings, spec.zoom))
    with (
        head(hub, "chessboard", scenario) as before,
        head(hub, "chessboard", twin) as after,
    ):
        hub.emit(PhaseStarted("board views", before.truth, knowledge, {}))
        try:
            run = principal_points_by_zoom(
                before, after, spec.zoom, np.random.default_rng(seed), spec.poses
            )
        except PrincipalPointError as error:
            return [], NotFound(str(error))
    return [], ZoomFixedPoints.of(run)


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment.zoom_fixed_points]``: :class:`ZoomSpec`."""
    block = table.section(ZOOM_TABLE) or Table({}, table.field("zoom_fixed_points"), table.ctx)
    zoom, poses, board_seed = (block.setting(d) for d in (_ZOOM, _POSES, _SEED))
    block.done()
    return {"block": ZoomSpec(zoom, poses, board_seed)}


# fmt: off
_ZOOM = Setting("zoom", ZoomSpec.zoom, 1.05, 3.0, "", "The focal length ratio of the second images.")
_POSES = Setting("poses", ZoomSpec.poses, 1, 100, "", "Chessboard poses rendered at both focal lengths.", integer=True)
_SEED = Setting("board_seed", None, 0, 2**32 - 1, "", "The seed of the board poses' draws (absent: the scenario's seed).", integer=True, optional=True)
#: ``[experiment.zoom_fixed_points]``, the scenario table only it reads.
ZOOM_TABLE = Section("experiment.zoom_fixed_points", "Each camera's principal point as the fixed point of a zoom (procedure `zoom_fixed_points`): chessboard images at the head's focal lengths and at `zoom` times them; only pixels enter the fit.", (_ZOOM, _POSES, _SEED))
# fmt: on


ZOOM_FIXED_POINTS = register(
    Procedure(
        "zoom_fixed_points",
        "chessboard",
        run_zoom_fixed_points,
        (ZoomFixedPoints, NotFound),
        summary=lambda result, paper: result.summary_lines(paper),
        ok_line=lambda result, measured: result.ok_line(measured),
        failures=lambda result: result.failures() if isinstance(result, NotFound) else (),
        rows=lambda result, log: result.log_rows(log),
        options=read_options,
        fixations=lambda scenario: 0,
        keys=(ZOOM_TABLE,),
        rank=90,
    )
)


__all__ = [
    "ZOOM_FIXED_POINTS",
    "NotFound",
    "ZoomFixedPoints",
    "ZoomSpec",
    "read_options",
    "run_zoom_fixed_points",
]
