"""What a recording logs of the results: each measurement (estimate, error, the
measurements' table), each live pursuit frame, the calibration's and the summary's
documents, and what the procedure adds (:attr:`headsim.scenario.registry.Procedure.rows`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import rerun as rr

from headsim.active.calibration_report import CalibrationReport
from headsim.run.outcomes import MeasurementRecord, RunResult
from headsim.run.recording_layout import (
    GREEN,
    GREY,
    RED,
    UI_RADIUS,
    WHITE,
)
from headsim.run.recording_scene import SceneLogging
from headsim.run.summary import summary_text
from headsim.scenario.registry import get
from headsim.sim import names


class ResultsLogging(SceneLogging):
    """The results in a recording; :class:`headsim.run.recording.Recorder` sets the state."""

    estimates: dict[str, tuple[np.ndarray, np.ndarray, bool]]
    _labels: dict[str, str]
    _rows: list[str]
    _pursuit_trail: list[np.ndarray]
    effective_alpha_e: tuple[float, float]
    world_from_head_start: np.ndarray

    def measured(self, record: MeasurementRecord) -> None:
        m = record.measurement
        self.current_step = record.step
        self._time()
        label = m.name
        if record.time_s is not None:
            label += f" t={record.time_s:g}s"
        if self.scenario.experiment.procedure == "calibration":
            label += f" ({record.knowledge})"
        self.estimates[f"{record.step}"] = (m.estimate_world_m, m.truth_world_m, m.ok)
        self._labels[f"{record.step}"] = label
        done = [(k, e, t) for k, (e, t, ok) in self.estimates.items() if ok]
        if done:
            self.rec.log(
                "/world/estimate",
                rr.Points3D(
                    [e for _, e, _ in done],
                    radii=UI_RADIUS,
                    colors=[GREEN] * len(done),
                    labels=[self._labels[k] for k, _, _ in done],
                    show_labels=False,
                ),
            )
            self.rec.log(
                "/world/error",
                rr.LineStrips3D([[t, e] for _, e, t in done], colors=[RED] * len(done)),
            )
        error = float(np.linalg.norm(m.error_head_m))
        if math.isfinite(error):
            self.rec.log("/measurements/error_mm", rr.Scalars([error * 1000.0]))
            self.rec.log("/measurements/error_pct_of_depth", rr.Scalars([m.error_pct_of_depth]))
        self.rec.log("/measurements/renders", rr.Scalars([float(m.renders)]))
        residuals = [abs(r) for r in m.servo_residual_px if math.isfinite(r)]
        if residuals:
            self.rec.log("/measurements/servo_residual_px", rr.Scalars([max(residuals)]))
        self._rows.append(
            f"| {record.step} | {label} | {m.status_text} | {error * 1000.0:.2f} | "
            f"{m.error_pct_of_depth:.3f} | {m.renders} | "
            f"{max(residuals) if residuals else float('nan'):.2f} |"
        )
        self.rec.log(
            "/results/measurements",
            rr.TextDocument(
                "# Measurements\n\n| step | target | status | error mm | % of depth | renders "
                "| residual px |\n|---|---|---|---|---|---|---|\n" + "\n".join(self._rows) + "\n",
                media_type=rr.MediaType.MARKDOWN,
            ),
        )
        self.flush()

    def pursued(self, record: Any, frame: int) -> None:
        """A live pursuit frame: truth, estimate and error on the frame timeline."""
        self.current_frame = frame
        self._time()
        spec = self.scenario.scene.pursuit
        if not self._pursuit_trail and spec is not None:
            times = spec.sample_times(0.02)
            path = [
                spec.path.position(float(t)) for t in times if spec.visibility.visible(float(t))
            ]
            if len(path) > 1:
                self.rec.log(
                    "/world/pursuit/path",
                    rr.LineStrips3D([np.array(path)], colors=[GREY], labels=["path"]),
                    static=True,
                )
        truth, estimate = record.truth_world_m, record.estimate_world_m
        if truth is not None:
            self.rec.log("/world/truth", rr.Points3D([truth], radii=0.003, colors=[WHITE]))
        else:
            self.rec.log("/world/truth", rr.Clear(recursive=False))
        for index, cam in enumerate(names.CAMERAS):
            uv = record.uv_px[index]
            if uv is None:
                self.rec.log(f"/world/head/{cam}/features", rr.Clear(recursive=False))
                continue
            self.rec.log(
                f"/world/head/{cam}/features", rr.Points2D([uv], radii=4.0, colors=[GREEN])
            )
        if record.error_px is not None:
            for index, cam in enumerate(names.CAMERAS):
                self.rec.log(
                    f"/servo/{cam}/u_error_px", rr.Scalars([float(record.error_px[index])])
                )
        if estimate is None or not np.all(np.isfinite(estimate)):
            self.rec.log("/world/estimate", rr.Clear(recursive=False))
            self.rec.log("/world/error", rr.Clear(recursive=False))
            return
        self._pursuit_trail.append(np.asarray(estimate, float))
        self.rec.log("/world/estimate", rr.Points3D([estimate], radii=0.004, colors=[GREEN]))
        self.rec.log(
            "/world/pursuit/estimates",
            rr.Points3D(np.array(self._pursuit_trail), radii=0.0015, colors=[GREEN]),
        )
        if truth is not None:
            error = float(np.linalg.norm(estimate - truth))
            self.rec.log("/world/error", rr.LineStrips3D([[truth, estimate]], colors=[RED]))
            self.rec.log("/measurements/error_mm", rr.Scalars([error * 1000.0]))
            depth = float(np.linalg.norm(truth - self.world_from_head_start[:3, 3]))
            self.rec.log("/measurements/error_pct_of_depth", rr.Scalars([100.0 * error / depth]))

    def calibrated(self, calibration: CalibrationReport) -> None:
        self._time()
        self.rec.log(
            "/results/calibration",
            rr.TextDocument(calibration_markdown(calibration), media_type=rr.MediaType.MARKDOWN),
        )
        self.flush()

    def finished(self, result: RunResult) -> None:
        self._time()
        if result.experiment is not None:
            get(self.scenario.experiment.procedure).rows(result.experiment, self)
        text = summary_text(result)
        self.rec.log(
            "/results/summary",
            rr.TextDocument(f"```\n{text}\n```", media_type=rr.MediaType.MARKDOWN),
        )


def calibration_markdown(report: CalibrationReport) -> str:
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


__all__ = ["ResultsLogging", "calibration_markdown"]
