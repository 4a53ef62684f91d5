"""results.json from the typed results: the one place that knows its keys and their order.

``results.json`` (:mod:`headsim.runs.results_reference` documents every key) holds
no wall time and no timestamp: the same scenario, seed and software give the
same bytes.  SI units (m, rad, px); NaN becomes null when
:func:`headsim.files.write_json_atomic` writes it.  The ``calibration`` block,
which a calibration file (head.json) holds too, is
:func:`headsim.active.calibration_report.calibration_block`'s.
"""

from __future__ import annotations

import platform
from dataclasses import asdict
from importlib import metadata
from typing import Any

import cv2
import mujoco
import numpy as np

from headsim.active.calibration_report import calibration_block
from headsim.procedures.contract import get
from headsim.runs.accuracy import MeasurementSummary, summaries
from headsim.runs.outcomes import FixationScore, MeasurementRecord, RunOutcome
from headsim.scenario.spec import experiment_record
from headsim.sim.settings import settings_record
from headsim.version import __version__

#: Version of the results.json layout; bumped when a key changes meaning or goes.
RESULTS_SCHEMA = "headsim.results/2"

#: Keys of results.json and of each measurement in it (:mod:`headsim.runs.results_reference` gives each its meaning).
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
    "fixation",
)


def software_versions() -> dict[str, str]:
    """Versions of what produced the numbers."""

    def version(package: str) -> str:
        try:
            return metadata.version(package)
        except metadata.PackageNotFoundError:
            return "not installed"

    return {
        "headsim": __version__,
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
        "fixation": None if record.fixation is None else fixation_entry(record.fixation),
    }


def fixation_entry(f: FixationScore) -> dict[str, Any]:
    """A markerless target's landing truth as results.json holds it (NaN becomes null)."""
    return {
        "vergence_error_deg": f.vergence_error_deg,
        "error_deg": list(f.error_deg),
        "error_m": list(f.error_m),
        "landed": list(f.landed),
        "landed_world_m": [None if p is None else list(p) for p in f.landed_world_m],
        "click_error_px": f.click_error_px,
        "image_error_px": list(f.image_error_px),
        "match_sigma_px": f.match_sigma_px,
        "match_score": f.match_score,
        "match_ambiguity": f.match_ambiguity,
        "match_status": f.match_status,
        "false_fixation": f.false_fixation,
        "false_fixation_limit_m": f.false_fixation_limit_m,
        "match_error_px": f.match_error_px,
        "wrong_match": f.wrong_match,
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
            {
                "band": b.band,
                "count": b.count,
                "asked": b.asked,
                "error_pct_of_depth_rms": b.error_pct_of_depth_rms,
            }
            for b in s.by_depth
        ],
        "scanned": s.scanned,
        "scan_renders": s.scan_renders,
        "outside_start_view": asdict(s.outside_start_view),
    }


# -- each procedure's experiment ---------------------------------------------------------


def experiment_block(procedure: str, experiment: object | None) -> dict[str, Any]:
    """results.json's ``experiment``: the procedure, then its result's fields (none if it did not run)."""
    return {
        "procedure": procedure,
        **({} if experiment is None else get(procedure).fields(experiment)),
    }


def results_payload(result: RunOutcome) -> dict[str, Any]:
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
            "experiment": experiment_record(s.experiment),
        },
        "seed": s.seed,
        "status": "ok" if result.ok else "failed",
        "failures": list(result.failures),
        "software": software_versions(),
        "settings": {**settings_record(s.settings), "settle_mode": s.settle_mode},
        # The truth above; what the head believes (and its estimators use) here.
        "belief": {**asdict(s.settings.believed), "sources": s.believed_from},
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
    "experiment_block",
    "fixation_entry",
    "measurement_entry",
    "results_payload",
    "software_versions",
    "summary_entry",
]
