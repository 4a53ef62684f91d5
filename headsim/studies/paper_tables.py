"""Tables V/VI on the reproduction's one head, with its one calibration (``headsim reproduce``).

:mod:`headsim.studies.study` calibrates every method itself, on two base heads, for
ten conditions.  ``headsim reproduce`` measures what the paper's Tables V
and VI and its changed focal length need, on the one head the rest of the
reproduction uses, calibrated once:

- ``stereo``: Zhang's chessboard calibration of this head at eye angle 0
  (:func:`zhang_calibration`, made once and kept for every condition);
- ``active_centre`` (Table VI): the one Sec. V calibration (``head.json``)'s
  initial directions, nothing else;
- ``active_v_known`` (Table V): the same with Zhang's principal-point v;
- ``active_extended``: ``head.json``'s whole knowledge (its extended fit);
- ``active_fixed_point`` and ``active_refound`` (beyond the paper, but what
  shows its insensitivity to the focal length here): the principal point
  found as a zoom's fixed point, the servo on its column, with their own
  Sec. V calibration on that column (:func:`fixed_point_calibration`, made
  once beside Zhang's); ``active_refound`` finds the fixed point again on
  the head it measures.

Conditions: the six target positions as calibrated, then the cameras zoomed
1.5x with every calibration kept.  The three active methods servo on the
same column (the image centre) and differ only in what Model 2 computes from
the images, so each target is servoed once and every active method's
estimate is computed from those same images (:func:`measure_paired`; the
renders are counted once, on ``active_centre``).  The study's other parts (a
second base head with centred principal points, the 0.7x zoom,
principal-point and k1 changes) are left to ``headsim study``.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from headsim.active.measurement import HeadKnowledge, Measurement
from headsim.active.principal import PrincipalPointRun, zoomed
from headsim.estimators import model2
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import start_views
from headsim.stereo.calibration import StereoCalibration
from headsim.studies.calibrations import calibration_positions, zhang_stereo, zoom_fixed_points
from headsim.studies.catalogue import Experiment, ExperimentResult
from headsim.studies.conditions import Condition, ConditionResult
from headsim.studies.methods import METHODS, StudyConfig
from headsim.studies.scenario_runs import calibration_run
from headsim.studies.target_errors import (
    TargetError,
    model2_errors,
    model2_measurements,
    stereo_errors,
    summarise,
)
from headsim.studies.targets import table_targets

#: The active methods that servo on the image centre's column.
CENTRE_METHODS = METHODS[1:4]
#: The active method whose servo runs (the others reuse its images).
SERVOED = "active_centre"
#: The paper's changed focal length, with every calibration kept.
ZOOM = 1.5


def zhang_calibration(settings: HeadSettings, config: StudyConfig) -> tuple[StereoCalibration, int]:
    """Zhang's calibration of ``settings``' pair (as :func:`headsim.studies.calibrations.zhang_stereo`),
    and the renders it took."""
    calibration, views = zhang_stereo(settings, config)
    return calibration, views.renders


@dataclass(frozen=True)
class FixedPoint:
    """The zoom fixed points of the head as calibrated and the Sec. V calibration on
    their columns, and the renders both took."""

    principal: PrincipalPointRun
    #: What Sec. V on the fixed points' columns taught the head.
    calibrated: HeadKnowledge
    #: Its effective initial directions minus the truth, rad (camera 1, 2).
    alpha_e_error_rad: tuple[float, float]
    renders: int
    #: The head and seed the fixed points were found on (None: not recorded).
    settings: HeadSettings | None = None
    seed: int | None = None

    def knowledge(self, refound: PrincipalPointRun | None = None) -> HeadKnowledge:
        """``active_fixed_point``'s knowledge, or with ``refound``'s columns and rows
        (``active_refound``)."""
        if refound is None:
            return self.calibrated
        (u1, v1), (u2, v2) = refound.principal_px
        return replace(self.calibrated, u0=(u1, u2), v0=(v1, v2))


def fixed_point_calibration(settings: HeadSettings, config: StudyConfig) -> FixedPoint:
    """The fixed points of a zoom (images only) and Sec. V with the servo on their columns."""
    principal = zoom_fixed_points(settings, config)
    positions = calibration_positions(start_views(settings), settings, config)
    (u1, _), (u2, _) = principal.principal_px
    knowledge, report = calibration_run(settings, positions, goal_columns_px=(u1, u2))
    renders = principal.renders + report.renders.total
    assert report.alpha_e_error_rad is not None  # calibration_run raises if it failed
    error1, error2 = report.alpha_e_error_rad
    return FixedPoint(principal, knowledge, (error1, error2), renders, settings, config.seed)


def active_knowledge(stored: HeadKnowledge, zhang: StereoCalibration) -> dict[str, HeadKnowledge]:
    """Each active method's knowledge: from the one Sec. V calibration and Zhang's v0."""
    if stored.u0 != (None, None):
        raise ValueError("the calibration's servo column is not the image centre's")
    return {
        "active_v_known": HeadKnowledge(
            alpha_e=stored.alpha_e, v0=(zhang.cam1.K[1, 2], zhang.cam2.K[1, 2])
        ),
        "active_centre": HeadKnowledge(alpha_e=stored.alpha_e),
        "active_extended": stored,
    }


def recompute(
    settings: HeadSettings, measured: Measurement, knowledge: HeadKnowledge
) -> np.ndarray:
    """Model 2's estimate in H, m, from ``measured``'s fixations and images by the head
    ``settings`` with ``knowledge``.

    ``knowledge`` must have ``measured``'s servo column (u0); only what Model
    2 computes differs (alpha_e, v0, kx/ky, line-of-sight offsets).
    """
    d = measured.details
    (u10, v10), (u20, v20) = (
        knowledge.reference_of(settings, 1),
        knowledge.reference_of(settings, 2),
    )
    estimate = model2(
        [d["alpha1_rad"]],
        [d["alpha2_rad"]],
        np.array([[d["u11_px"], d["v11_px"]]]),
        np.array([[d["u21_px"], d["v21_px"]]]),
        knowledge.head_belief_of(settings).baseline_m,
        uv10=(u10, v10),
        uv20=(u20, v20),
        alpha_e=knowledge.alpha_e,
        gamma1=[d["gamma1_rad"]],
        gamma2=[d["gamma2_rad"]],
        kx_over_ky=knowledge.kx_over_ky,
        los_offset_m=knowledge.line_of_sight_offsets_of(settings),
    )
    if not bool(estimate.valid[0]):
        return np.full(3, np.nan)
    return np.asarray(estimate.positions[0], dtype=float)


def shared_errors(
    settings: HeadSettings, measured: Sequence[Measurement], knowledges: dict[str, HeadKnowledge]
) -> list[TargetError]:
    """Each of ``knowledges``' methods on the images of ``measured`` (one per target, taken
    with ``knowledges[SERVOED]``), whose renders count on :data:`SERVOED` only."""
    out = []
    for index, m in enumerate(measured):
        for method, knowledge in knowledges.items():
            if not m.ok:
                estimate, status = np.full(3, np.nan), m.status_text
            elif method == SERVOED:
                estimate, status = m.estimate_head_m, "ok"
            else:
                estimate = recompute(settings, m, knowledge)
                status = "ok" if bool(np.all(np.isfinite(estimate))) else "estimate invalid"
            own = m.renders if method == SERVOED else 0
            out.append(TargetError(method, index, m.truth_head_m, estimate, status, own))
    return out


def measure_paired(
    settings: HeadSettings,
    zhang: StereoCalibration,
    knowledges: dict[str, HeadKnowledge],
    targets_head: np.ndarray,
    fixed: FixedPoint | None = None,
    config: StudyConfig | None = None,
) -> list[TargetError]:
    """The red marker at each of ``targets_head`` (N, 3) m, each a run through the runner:
    stereo, then one servo for the image-centre methods (``knowledges``), then with
    ``fixed`` the fixed-point methods, each its own servo (``active_refound`` first
    finds the fixed points on ``settings``, seeded as ``config``'s).  The errors in
    target order, then that order of methods."""
    config = config or StudyConfig()
    targets = np.atleast_2d(np.asarray(targets_head, dtype=float))
    methods = ["stereo", *knowledges]
    out: list[TargetError] = []
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        out += stereo_errors(settings, zhang, targets, folder)
        shared = model2_measurements(settings, SERVOED, knowledges[SERVOED], targets, folder)
        out += shared_errors(settings, shared, knowledges)
        if fixed is not None:
            # On the head they were calibrated on, found again they are the same images
            # and the same answer (deterministic from the seed): taken from ``fixed``.
            refound = (
                fixed.principal
                if fixed.settings == settings and fixed.seed == config.seed
                else zoom_fixed_points(settings, config)
            )
            for method, knowledge in (
                ("active_fixed_point", fixed.knowledge()),
                ("active_refound", fixed.knowledge(refound)),
            ):
                methods.append(method)
                out += model2_errors(settings, method, knowledge, targets, folder)
    order = {method: k for k, method in enumerate(methods)}
    return sorted(out, key=lambda e: (e.index, order[e.method]))


def tables_experiment(settings: HeadSettings, config: StudyConfig) -> Experiment:
    """The conditions: the table targets as calibrated, then zoomed :data:`ZOOM` x (kept)."""
    targets = table_targets(config.table_targets)
    group = config.preset
    return Experiment(
        name="tables_v_vi",
        title="Tables V/VI on the reproduction's head, then the focal length x1.5",
        kind="compare",
        parameter="condition",
        base={group: settings},
        conditions=(
            Condition(group, "as calibrated", 0.0, settings, "kept", targets),
            Condition(group, f"zoom {ZOOM:g}x", ZOOM, zoomed(settings, ZOOM), "kept", targets),
        ),
        methods=METHODS,
    )


def run_tables(
    settings: HeadSettings,
    zhang: StereoCalibration,
    stored: HeadKnowledge,
    config: StudyConfig,
    fixed: FixedPoint | None = None,
) -> ExperimentResult:
    """Every condition of :func:`tables_experiment`, with ``zhang``, ``stored`` and
    ``fixed`` (None: without the fixed-point methods) kept."""
    start = time.perf_counter()
    methods = METHODS if fixed is not None else METHODS[:4]
    experiment = replace(tables_experiment(settings, config), methods=methods)
    knowledges = active_knowledge(stored, zhang)
    ordered = {m: knowledges[m] for m in CENTRE_METHODS}
    results = []
    for condition in experiment.conditions:
        began = time.perf_counter()
        errors = measure_paired(
            condition.head, zhang, ordered, condition.targets_head, fixed, config
        )
        summaries = tuple(summarise(errors, m) for m in methods)
        results.append(
            ConditionResult(condition, tuple(errors), summaries, time.perf_counter() - began)
        )
    return ExperimentResult(
        experiment=experiment,
        config=replace(config),
        results=tuple(results),
        calibrations=(),
        seconds=time.perf_counter() - start,
    )
