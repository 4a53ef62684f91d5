"""Measuring targets with every method on one head, and each method's errors summarised
(estimate minus truth in H, m; "% of depth" divides by the true z_h)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.active.look import look_once
from headsim.active.model2 import measure_model2
from headsim.active.principal import PROBE_ZOOM, principal_points_by_zoom, zoomed
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.stereo.triangulation import measure_point_stereo
from headsim.stereo.views import StereoError
from headsim.studies.calibrations import Calibrations
from headsim.studies.methods import METHODS, SWEEP_METHODS, TARGET, StudyConfig
from headsim.studies.targets import place_in_head


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


def measure_methods(
    settings: HeadSettings,
    calibrations: Calibrations,
    targets_head: np.ndarray,
    methods: Sequence[str] = SWEEP_METHODS,
    config: StudyConfig | None = None,
) -> list[TargetError]:
    """Measure the red marker at each of ``targets_head`` (N, 3) m with each method.

    The head is ``settings`` (which may differ from the one calibrated);
    every method uses ``calibrations`` as they are, except that
    ``active_refound`` first finds the zoom fixed points on ``settings``
    (``config``'s seed and poses).
    """
    config = config or StudyConfig()
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown methods {unknown}; allowed: {', '.join(METHODS)}")
    out: list[TargetError] = []
    with HeadSim("default", settings) as sim:
        servo = EyeServo(sim)
        refound = None
        if "active_refound" in methods:
            with (
                HeadSim("chessboard", settings) as before,
                HeadSim("chessboard", zoomed(settings, PROBE_ZOOM)) as after,
            ):
                refound = principal_points_by_zoom(
                    before,
                    after,
                    PROBE_ZOOM,
                    np.random.default_rng(config.seed + 1),
                    config.principal_poses,
                )
        for index, p_head in enumerate(np.atleast_2d(np.asarray(targets_head, dtype=float))):
            place_in_head(sim, TARGET.name, p_head)
            truth = sim.position(TARGET.name, "head")
            for method in methods:
                start = sim.render_count
                if method == "stereo":
                    try:
                        m = measure_point_stereo(
                            sim, calibrations.stereo, TARGET.name, look=look_once
                        )
                        estimate, status = m.p_head, "ok"
                    except StereoError as error:
                        estimate, status = np.full(3, np.nan), str(error)
                else:
                    m2 = measure_model2(sim, servo, TARGET, calibrations.knowledge(method, refound))
                    estimate, status = m2.estimate_head_m, m2.status_text
                out.append(
                    TargetError(method, index, truth, estimate, status, sim.render_count - start)
                )
                sim.move(eye=0.0)
    return out


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
