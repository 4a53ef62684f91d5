"""The Sec. V calibration's report, and its ``calibration`` block both ways.

The block is what results.json's ``calibration`` holds and what a calibration
file (head.json, :mod:`headsim.active.calibration_file`) stores;
:func:`calibration_from_block` reads back what :func:`calibration_block` wrote.
Units are in the names: m, rad, px; positions in W unless named otherwise.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from headsim.active.failure import Failure, FailureCause
from headsim.estimators.result import Status
from headsim.sim.events import RenderCounts


@dataclass(frozen=True)
class CalibrationLayout:
    """Where the calibration ball was placed: the layout's kind and settings, and each position."""

    kind: str
    near_fraction: float | None
    depth_m: list[float]
    lateral: float
    vertical: float
    #: (N, 3) as drawn, or as read back from JSON
    positions_world_m: np.ndarray | list[list[float]]


@dataclass(frozen=True)
class VerticalReference:
    """The extended calibration's v0, px, and kx/ky of each camera, beside the truth."""

    v0_px: list[float]
    v0_std_px: list[float]
    v0_truth_px: list[float]
    kx_over_ky: list[float]
    kx_over_ky_std: list[float]
    kx_over_ky_truth: list[float]


@dataclass(frozen=True)
class LinesOfSightFit:
    """The extended line-of-sight fit beside the truth.

    ``std_errors_*``: 1-sigma of alpha_e, rad, and of the offsets s1, s2, m;
    ``covariance``: of (alpha_e1, alpha_e2, s1, s2).
    """

    alpha_e_rad: list[float]
    offset_m: list[float]
    std_errors_alpha_e_rad: list[float]
    std_errors_offset_m: list[float]
    offset_truth_m: list[float]
    covariance: list[list[float]]
    effective_baseline_m: float
    effective_baseline_std_m: float
    effective_baseline_truth_m: float
    separable: bool
    message: str


@dataclass(frozen=True)
class KnowledgeReport:
    """What the calibration taught the head (its :class:`HeadKnowledge`, as numbers)."""

    alpha_e_rad: list[float]
    v0_px: list[float | None]
    kx_over_ky: list[float]
    u0_px: list[float | None]
    los_offset_m: list[float] | None


@dataclass(frozen=True)
class PositionOutcome:
    """One calibration position: fixated (``failure`` None) or why not."""

    failure: Failure | None

    @property
    def status_text(self) -> str:
        """ "ok", or the failure's message (results.json's "status")."""
        return "ok" if self.failure is None else self.failure.message


@dataclass(frozen=True)
class CalibrationSource:
    """Where a calibration read from a file came from (``[experiment.calibration] from``)."""

    path: str
    scenario: str
    seed: int
    head_hash: str
    #: the renders the calibration took when it ran, by kind (None if the file does not
    #: say: one written before calibration blocks had ``render_counts``, whose
    #: ``renders`` left the previews out)
    render_counts: RenderCounts | None


@dataclass(frozen=True)
class CalibrationReport:
    """The Sec. V calibration: results.json's ``calibration`` block.

    ``status``: OK, or FAILED with ``detail`` "failed: why".  ``layout`` is None
    when the ball positions could not be laid out (nothing below it was tried);
    the fit's fields are None when the fit did not run.  ``renders``: every image the
    calibration drew, by kind (previews included; none for one read from a file).  ``rendered_frames``
    (pixels rendered, in full frames) is set by ``headsim calibrate`` only;
    ``source`` only for a calibration read from a file.
    """

    status: Status
    detail: str
    targets: int
    fixated: int
    renders: RenderCounts
    positions: tuple[PositionOutcome, ...]
    layout: CalibrationLayout | None = None
    depth_noise_m: float = 0.0
    position_noise_m: float = 0.0
    lines_of_sight_fit: bool = False
    extended: bool = False
    alpha_e_rad: list[float] | None = None
    alpha_e_std_rad: list[float] | None = None
    alpha_e_covariance_rad2: list[list[float]] | None = None
    alpha_e_truth_rad: list[float] | None = None
    alpha_e_error_rad: list[float] | None = None
    alpha_e_paper_rad: list[float] | None = None
    converged: bool = False
    depth_residual_rms_m: float | None = None
    vertical_reference: VerticalReference | None = None
    lines_of_sight: LinesOfSightFit | None = None
    knowledge: KnowledgeReport | None = None
    rendered_frames: float | None = None
    source: CalibrationSource | None = None

    @property
    def ok(self) -> bool:
        return self.status is Status.OK

    @property
    def status_text(self) -> str:
        """ "ok", or "failed: why" (results.json's "status")."""
        return "ok" if self.ok else self.detail


def render_counts_from_block(block: dict[str, Any]) -> RenderCounts | None:
    """The ``render_counts`` of a ``calibration`` block read back (None: the block has none,
    as one written before renders counted previews, whose ``renders`` counted them apart)."""
    entry = block.get("render_counts")
    return None if entry is None else RenderCounts.from_dict(entry)


def _position_entry(p: PositionOutcome) -> dict[str, Any]:
    return {"status": p.status_text, "failure": None if p.failure is None else p.failure.as_dict()}


def _lines_entry(lines: LinesOfSightFit) -> dict[str, Any]:
    return {
        "alpha_e_rad": lines.alpha_e_rad,
        "offset_m": lines.offset_m,
        "std_errors": {
            "alpha_e_rad": lines.std_errors_alpha_e_rad,
            "offset_m": lines.std_errors_offset_m,
        },
        "offset_truth_m": lines.offset_truth_m,
        "covariance": lines.covariance,  # (alpha_e1, alpha_e2, s1, s2)
        "effective_baseline_m": lines.effective_baseline_m,
        "effective_baseline_std_m": lines.effective_baseline_std_m,
        "effective_baseline_truth_m": lines.effective_baseline_truth_m,
        "separable": lines.separable,
        "message": lines.message,
    }


def calibration_block(report: CalibrationReport) -> dict[str, Any]:
    """The calibration as results.json's ``calibration`` block (and head.json's) holds it."""
    block: dict[str, Any] = {
        "status": report.status_text,
        "targets": report.targets,
        "fixated": report.fixated,
        "render_counts": report.renders.as_dict(),
    }
    layout = report.layout
    if layout is not None:
        block.update(
            layout={
                "kind": layout.kind,
                "near_fraction": layout.near_fraction,
                "depth_m": layout.depth_m,
                "lateral": layout.lateral,
                "vertical": layout.vertical,
                "positions_world_m": layout.positions_world_m,
            },
            depth_noise_m=report.depth_noise_m,
            position_noise_m=report.position_noise_m,
            lines_of_sight_fit=report.lines_of_sight_fit,
            extended=report.extended,
            alpha_e_rad=report.alpha_e_rad,
            alpha_e_std_rad=report.alpha_e_std_rad,
            alpha_e_covariance_rad2=report.alpha_e_covariance_rad2,
            alpha_e_truth_rad=report.alpha_e_truth_rad,
            alpha_e_error_rad=report.alpha_e_error_rad,
            alpha_e_paper_rad=report.alpha_e_paper_rad,
            converged=report.converged,
            depth_residual_rms_m=report.depth_residual_rms_m,
            vertical_reference=None
            if report.vertical_reference is None
            else asdict(report.vertical_reference),
            lines_of_sight=None
            if report.lines_of_sight is None
            else _lines_entry(report.lines_of_sight),
            knowledge=None if report.knowledge is None else asdict(report.knowledge),
        )
    block["positions"] = [_position_entry(p) for p in report.positions]
    if report.rendered_frames is not None:
        block["rendered_frames"] = report.rendered_frames
    if report.source is not None:
        counts = report.source.render_counts
        block["from"] = {
            **asdict(report.source),
            "render_counts": None if counts is None else counts.as_dict(),
        }
    return block


def _failure(entry: dict[str, Any] | None) -> Failure | None:
    if entry is None:
        return None
    return Failure(FailureCause(entry["cause"]), entry["stage"], entry["camera"], entry["detail"])


def calibration_from_block(
    block: dict[str, Any],
    *,
    renders: RenderCounts | None = None,
    source: CalibrationSource | None = None,
) -> CalibrationReport:
    """The report of a ``calibration`` block read back from JSON (head.json), as written.

    ``renders`` and ``source`` replace the block's own (a calibration read from a file;
    a block written before renders counted previews has no ``render_counts``).
    """
    if renders is None:
        renders = RenderCounts.from_dict(block["render_counts"])
    status = block["status"]
    layout = block.get("layout")
    lines = block.get("lines_of_sight")
    vertical = block.get("vertical_reference")
    knowledge = block.get("knowledge")
    return CalibrationReport(
        status=Status.OK if status == "ok" else Status.FAILED,
        detail="" if status == "ok" else status,
        targets=block["targets"],
        fixated=block["fixated"],
        renders=renders,
        positions=tuple(PositionOutcome(_failure(p["failure"])) for p in block["positions"]),
        layout=None if layout is None else CalibrationLayout(**layout),
        depth_noise_m=block.get("depth_noise_m", 0.0),
        position_noise_m=block.get("position_noise_m", 0.0),
        lines_of_sight_fit=block.get("lines_of_sight_fit", False),
        extended=block.get("extended", False),
        alpha_e_rad=block.get("alpha_e_rad"),
        alpha_e_std_rad=block.get("alpha_e_std_rad"),
        alpha_e_covariance_rad2=block.get("alpha_e_covariance_rad2"),
        alpha_e_truth_rad=block.get("alpha_e_truth_rad"),
        alpha_e_error_rad=block.get("alpha_e_error_rad"),
        alpha_e_paper_rad=block.get("alpha_e_paper_rad"),
        converged=block.get("converged", False),
        depth_residual_rms_m=block.get("depth_residual_rms_m"),
        vertical_reference=None if vertical is None else VerticalReference(**vertical),
        lines_of_sight=None
        if lines is None
        else LinesOfSightFit(
            alpha_e_rad=lines["alpha_e_rad"],
            offset_m=lines["offset_m"],
            std_errors_alpha_e_rad=lines["std_errors"]["alpha_e_rad"],
            std_errors_offset_m=lines["std_errors"]["offset_m"],
            offset_truth_m=lines["offset_truth_m"],
            covariance=lines["covariance"],
            effective_baseline_m=lines["effective_baseline_m"],
            effective_baseline_std_m=lines["effective_baseline_std_m"],
            effective_baseline_truth_m=lines["effective_baseline_truth_m"],
            separable=lines["separable"],
            message=lines["message"],
        ),
        knowledge=None if knowledge is None else KnowledgeReport(**knowledge),
        rendered_frames=block.get("rendered_frames"),
        source=source,
    )


__all__ = [
    "CalibrationLayout",
    "CalibrationReport",
    "CalibrationSource",
    "KnowledgeReport",
    "LinesOfSightFit",
    "PositionOutcome",
    "VerticalReference",
    "calibration_block",
    "calibration_from_block",
    "render_counts_from_block",
]
