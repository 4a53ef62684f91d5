"""Measuring targets with every method on one head, each method a run of its own through
the runner, and each method's errors summarised (estimate minus truth in H, m; "% of
depth" divides by the true z_h)."""

from __future__ import annotations

import math
import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.procedures.stereo import StoredStereoResult
from headsim.runs.runner import run_scenario
from headsim.sim.settings import HeadSettings
from headsim.stereo.calibration import StereoCalibration
from headsim.stereo.calibration_file import write_stereo_calibration
from headsim.studies.calibrations import Calibrations, zoom_fixed_points
from headsim.studies.methods import METHODS, SWEEP_METHODS, TARGET, StudyConfig
from headsim.studies.scenario_runs import knowledge_file, scenario_with_head


@dataclass(frozen=True)
class TargetError:
    """One target measured by one method: truth and estimate in H, m.

    ``status``: "ok" or why the method failed (estimate NaN then).
    """

    method: str
    index: int
    truth_head_m: np.ndarray
    estimate_head_m: np.ndarray
    status: str
    renders: int

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def error_m(self) -> np.ndarray:
        """Estimate minus truth in H, m."""
        return self.estimate_head_m - self.truth_head_m

    @property
    def error_pct_depth(self) -> float:
        """3-D error as a percentage of the true depth z_h."""
        return float(100 * np.linalg.norm(self.error_m) / self.truth_head_m[2])


def _targets_scene(targets_head: np.ndarray) -> dict[str, Any]:
    """``[scene]``: the red marker at each of ``targets_head`` (N, 3), H at the start pose, m."""
    return {
        "targets": [
            {"name": f"point_{k}", "body": TARGET.name, "position_head_m": [float(v) for v in p]}
            for k, p in enumerate(targets_head)
        ]
    }


def stereo_errors(
    settings: HeadSettings, zhang: StereoCalibration, targets_head: np.ndarray, folder: Path
) -> list[TargetError]:
    """Each of ``targets_head`` (N, 3) m triangulated by the head ``settings`` with the stored
    calibration ``zhang`` (written to ``folder``), through the runner's ``stereo`` procedure."""
    source = write_stereo_calibration(folder / "zhang.json", zhang)
    doc = {
        "description": "A study's targets triangulated with a stored Zhang calibration",
        "experiment": {"procedure": "stereo", "stereo": {"from": str(source), "look": "once"}},
        "scene": _targets_scene(targets_head),
    }
    result = run_scenario(scenario_with_head(doc, "study_stereo", settings))
    stored = result.experiment
    if not isinstance(stored, StoredStereoResult):
        raise ValueError(f"study stereo run failed: {'; '.join(result.failures)}")
    return [
        TargetError("stereo", k, t.truth_head_m, t.estimate_head_m, t.status, renders)
        for k, (t, renders) in enumerate(zip(stored.targets, stored.target_renders, strict=True))
    ]


def model2_measurements(
    settings: HeadSettings,
    label: str,
    knowledge: HeadKnowledge,
    targets_head: np.ndarray,
    folder: Path,
) -> list[Measurement]:
    """Model 2 on each of ``targets_head`` (N, 3) m by the head ``settings`` told ``knowledge``
    (a calibration file ``label``.json in ``folder``), through the runner: one per target."""
    told = knowledge_file(folder / f"{label}.json", settings, knowledge)
    doc = {
        "description": "Model 2 on a study's targets with a method's knowledge",
        "experiment": {"procedure": "model2", "calibration": {"from": str(told)}},
        "scene": _targets_scene(targets_head),
    }
    result = run_scenario(scenario_with_head(doc, f"study_{label}", settings))
    if len(result.records) != len(targets_head):
        raise ValueError(f"study Model 2 run failed: {'; '.join(result.failures)}")
    return [r.measurement for r in result.records]


def model2_errors(
    settings: HeadSettings,
    method: str,
    knowledge: HeadKnowledge,
    targets_head: np.ndarray,
    folder: Path,
) -> list[TargetError]:
    """:func:`model2_measurements` as ``method``'s errors."""
    return [
        TargetError(method, k, m.truth_head_m, m.estimate_head_m, m.status_text, m.renders)
        for k, m in enumerate(
            model2_measurements(settings, method, knowledge, targets_head, folder)
        )
    ]


def measure_methods(
    settings: HeadSettings,
    calibrations: Calibrations,
    targets_head: np.ndarray,
    methods: Sequence[str] = SWEEP_METHODS,
    config: StudyConfig | None = None,
) -> list[TargetError]:
    """Measure the red marker at each of ``targets_head`` (N, 3) m with each method, one
    run each; the errors in target order, then ``methods``' order.

    The head is ``settings`` (which may differ from the one calibrated);
    every method uses ``calibrations`` as they are, except that
    ``active_refound`` first finds the zoom fixed points on ``settings``
    (``config``'s seed and poses).
    """
    config = config or StudyConfig()
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown methods {unknown}; allowed: {', '.join(METHODS)}")
    targets = np.atleast_2d(np.asarray(targets_head, dtype=float))
    refound = zoom_fixed_points(settings, config) if "active_refound" in methods else None
    out: list[TargetError] = []
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        for method in methods:
            if method == "stereo":
                out += stereo_errors(settings, calibrations.stereo, targets, folder)
            else:
                knowledge = calibrations.knowledge(method, refound)
                out += model2_errors(settings, method, knowledge, targets, folder)
    order = {method: k for k, method in enumerate(methods)}
    return sorted(out, key=lambda e: (e.index, order[e.method]))


@dataclass(frozen=True)
class Summary:
    """One method's errors over a condition's targets (ok ones; ``failed`` counts the others).

    RMS over targets of: the 3-D error (mm), the 3-D error / depth (%), the
    error in x and z only / depth (%), the error in y / depth (%); the worst
    3-D error / depth (%).
    """

    method: str
    ok: int
    failed: int
    rms_mm: float
    rms_pct_depth: float
    rms_xz_pct_depth: float
    rms_y_pct_depth: float
    max_pct_depth: float


def summarise(errors: Iterable[TargetError], method: str) -> Summary:
    """:class:`Summary` of ``method``'s entries in ``errors``."""
    rows = [e for e in errors if e.method == method]
    good = [e for e in rows if e.ok]
    if not good:
        nan = math.nan
        return Summary(method, 0, len(rows), nan, nan, nan, nan, nan)
    err = np.array([e.error_m for e in good])
    depth = np.array([e.truth_head_m[2] for e in good])
    rel = err / depth[:, None]
    return Summary(
        method=method,
        ok=len(good),
        failed=len(rows) - len(good),
        rms_mm=float(1e3 * np.sqrt(np.mean(np.sum(err**2, axis=1)))),
        rms_pct_depth=float(100 * np.sqrt(np.mean(np.sum(rel**2, axis=1)))),
        rms_xz_pct_depth=float(100 * np.sqrt(np.mean(rel[:, 0] ** 2 + rel[:, 2] ** 2))),
        rms_y_pct_depth=float(100 * np.sqrt(np.mean(rel[:, 1] ** 2))),
        max_pct_depth=float(100 * np.max(np.linalg.norm(rel, axis=1))),
    )
