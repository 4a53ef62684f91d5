"""results.json from the typed results: the one place that knows its keys and their order.

``results.json`` (README "Scenarios and results" documents every key) holds
no wall time and no timestamp: the same scenario, seed and software give the
same bytes.  SI units (m, rad, px); NaN becomes null when
:func:`headsim.files.write_json_atomic` writes it.  A calibration read
back from a file (``[experiment.calibration] from``) is parsed by
:func:`calibration_from_block`, the inverse of :func:`calibration_block`.
"""

from __future__ import annotations

import platform
from dataclasses import asdict
from importlib import metadata
from typing import Any

import cv2
import mujoco
import numpy as np

import headsim
from headsim.active.failure import Failure, FailureCause
from headsim.estimators.result import Status
from headsim.run.accuracy import MeasurementSummary, summaries
from headsim.run.outcomes import (
    CalibrationLayout,
    CalibrationReport,
    CalibrationSource,
    KnowledgeReport,
    LinesOfSightFit,
    MeasurementRecord,
    PositionOutcome,
    RunResult,
    VerticalReference,
)
from headsim.scenario.registry import get
from headsim.sim.events import RenderCounts

#: Version of the results.json layout; bumped when a key changes meaning or goes.
RESULTS_SCHEMA = "headsim.results/2"

#: Keys of results.json and of each measurement in it (README documents each).
RESULTS_KEYS = (
    "schema",
    "scenario",
    "seed",
    "status",
    "failures",
    "software",
    "settings",
    "belief",
    "render_counts",
    "rendered_frames",
    "calibration",
    "measurements",
    "summary",
    "experiment",
)
MEASUREMENT_KEYS = (
    "name",
    "method",
    "status",
    "failure",
    "knowledge",
    "step",
    "time_s",
    "estimate_head_m",
    "truth_head_m",
    "estimate_world_m",
    "truth_world_m",
    "error_head_m",
    "error_m",
    "depth_m",
    "error_pct_of_depth",
    "covariance_head_m2",
    "renders",
    "search_renders",
    "scan_renders",
    "servo_residual_px",
    "details",
)


def software_versions() -> dict[str, str]:
    """Versions of what produced the numbers."""

    def version(package: str) -> str:
        try:
            return metadata.version(package)
        except metadata.PackageNotFoundError:
            return "not installed"

    return {
        "headsim": headsim.__version__,
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "scipy": version("scipy"),  # not imported for it (0.1 s)
        "opencv": cv2.__version__,
        "rerun-sdk": version("rerun-sdk"),
    }


def measurement_entry(record: MeasurementRecord) -> dict[str, Any]:
    """One measurement as results.json holds it (NaN becomes null)."""
    m = record.measurement
    return {
        "name": m.name,
        "method": m.method.value,
        "status": m.status_text,
        "failure": None if m.failure is None else m.failure.as_dict(),
        "knowledge": record.knowledge,
        "step": record.step,
        "time_s": record.time_s,
        "estimate_head_m": m.estimate_head_m,
        "truth_head_m": m.truth_head_m,
        "estimate_world_m": m.estimate_world_m,
        "truth_world_m": m.truth_world_m,
        "error_head_m": m.error_head_m,
        "error_m": float(np.linalg.norm(m.error_head_m)),
        "depth_m": m.depth_m,
        "error_pct_of_depth": m.error_pct_of_depth,
        "covariance_head_m2": m.covariance_head_m2,
        "renders": m.renders,
        "search_renders": m.search_renders,
        "scan_renders": m.scan_renders,
        "servo_residual_px": list(m.servo_residual_px),
        "details": dict(m.details),
    }


def summary_entry(s: MeasurementSummary) -> dict[str, Any]:
    """One knowledge's statistics as results.json's ``summary`` holds them."""
    return {
        "count": s.count,
        "ok": s.ok,
        "failed": s.failed,
        "error_m_mean": s.error_m_mean,
        "error_m_max": s.error_m_max,
        "error_pct_of_depth_mean": s.error_pct_of_depth_mean,
        "error_pct_of_depth_max": s.error_pct_of_depth_max,
        "renders_per_point": s.renders_per_point,
        "servo_residual_px_max": s.servo_residual_px_max,
        "searched": s.searched,
        "search_renders": s.search_renders,
        "failure_causes": dict(s.failure_causes),
        "error_pct_of_depth_rms": s.error_pct_of_depth_rms,
        "by_depth": [
            {"band": b.band, "count": b.count, "error_pct_of_depth_rms": b.error_pct_of_depth_rms}
            for b in s.by_depth
        ],
        "scanned": s.scanned,
        "scan_renders": s.scan_renders,
        "outside_start_view": asdict(s.outside_start_view),
    }


def render_counts_from_block(block: dict[str, Any]) -> RenderCounts | None:
    """The ``render_counts`` of a ``calibration`` block read back (None: the block has none,
    as one written before renders counted previews, whose ``renders`` counted them apart)."""
    entry = block.get("render_counts")
    return None if entry is None else RenderCounts.from_dict(entry)


# -- the calibration block -------------------------------------------------------------


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


# -- each procedure's experiment ---------------------------------------------------------


def experiment_block(procedure: str, experiment: object | None) -> dict[str, Any]:
    """results.json's ``experiment``: the procedure, then its result's fields (none if it did not run)."""
    return {
        "procedure": procedure,
        **({} if experiment is None else get(procedure).fields(experiment)),
    }


def results_payload(result: RunResult) -> dict[str, Any]:
    """The results.json document (plain data; :func:`headsim.files.write_json_atomic` writes it)."""
    s = result.scenario
    edge = () if s.scene.acceptance is None else s.scene.acceptance.outside_start_view
    return {
        "schema": RESULTS_SCHEMA,
        "scenario": {
            "name": s.name,
            "file": s.path.name,
            "description": s.description,
            "procedure": s.experiment.procedure,
            "fast": s.fast,
            "preset": s.preset,
            "scene": asdict(s.scene),
            "experiment": asdict(s.experiment),
        },
        "seed": s.seed,
        "status": "ok" if result.ok else "failed",
        "failures": list(result.failures),
        "software": software_versions(),
        "settings": {**asdict(s.settings), "settle_mode": s.settle_mode},
        # The truth above; what the head believes (and its estimators use) here.
        "belief": asdict(s.settings.believed),
        "render_counts": result.renders.as_dict(),
        "rendered_frames": result.rendered_frames,
        "calibration": None
        if result.calibration is None
        else calibration_block(result.calibration),
        "measurements": [measurement_entry(r) for r in result.records],
        "summary": {
            label: summary_entry(m) for label, m in summaries(result.records, edge).items()
        },
        "experiment": experiment_block(s.experiment.procedure, result.experiment),
    }


__all__ = [
    "MEASUREMENT_KEYS",
    "RESULTS_KEYS",
    "RESULTS_SCHEMA",
    "calibration_block",
    "calibration_from_block",
    "experiment_block",
    "measurement_entry",
    "render_counts_from_block",
    "results_payload",
    "software_versions",
    "summary_entry",
]
