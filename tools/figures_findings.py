"""The findings page's figures (docs/findings.md): how far the paper's claims hold, over
seeds, each measured value beside the one its equation predicts.

Per seed, ``headsim reproduce``'s Tables V/VI experiment at full size on the paper preset
(its own Sec. V calibration draw, Zhang's stereo, the zoom fixed points), then the
focal length x1.5 with every calibration kept.  The predictions use the head's true
design only (its intrinsics, mount yaws, the servo's goal column): the paper's
equations of docs/equations.md, evaluated in closed form, and the same equations on the
exact forward model's images (:mod:`headsim.geometry.synthetic`, no rendering).
"""

from __future__ import annotations

import functools
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from figures_common import ROOT, SEEDS, median, seeds_label, span, writing

#: The findings' figure, written with ``--write`` (docs/findings.md shows it).
FIGURE = ROOT / "docs" / "findings.png"
#: Full size (False: the fast variants, for a quick look).
FULL = True
#: The methods of Tables V/VI the findings compare.
CENTRE, V_KNOWN, EXTENDED, FIXED, STEREO = (
    "active_centre",
    "active_v_known",
    "active_extended",
    "active_fixed_point",
    "stereo",
)


@functools.cache
def tables_run(seed: int) -> dict[str, Any]:
    """The Tables V/VI experiment at ``seed``, full size: ``result`` (the experiment's
    per-target errors) and ``summary`` (its rows)."""
    from headsim.studies.catalogue import STUDY_JOB
    from headsim.studies.reproduce_jobs import (
        calibrate_job,
        fixed_point_job,
        tables_job,
        zhang_job,
    )

    with tempfile.TemporaryDirectory(prefix="figures-findings-") as out:
        fast = not FULL
        after = {
            "calibration": calibrate_job("calibration", out, fast, seed, {}),
            "zhang": zhang_job("zhang", out, fast, seed, {}),
            "fixed_point": fixed_point_job("fixed_point", out, fast, seed, {}),
        }
        return tables_job(STUDY_JOB, out, fast, seed, after)


def _settings() -> Any:
    """The true head the tables run on (the calibration scenario's paper preset)."""
    from headsim.scenario.loading import load_scenario
    from headsim.studies.catalogue import TABLES_HEAD

    return load_scenario(TABLES_HEAD).settings


def _errors(run: dict[str, Any], condition: int, method: str) -> tuple[np.ndarray, np.ndarray]:
    """Truths (N, 3) and errors (N, 3), m, of ``method``'s measured targets in a condition
    (0: as calibrated, 1: the focal length x1.5)."""
    rows = [e for e in run["result"].results[condition].errors if e.method == method and e.ok]
    truth = np.array([e.truth_head_m for e in rows])
    return truth, np.array([e.error_m for e in rows])


def _rms_pct(values: np.ndarray) -> float:
    return float(100.0 * np.sqrt(np.mean(values**2)))


def xz_pct(truth: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Each target's x/z error, % of depth (the norm of its x and z errors)."""
    return 100.0 * np.hypot(error[:, 0], error[:, 2]) / truth[:, 2]


def _rms_3d_mm(error: np.ndarray) -> float:
    return float(1e3 * np.sqrt(np.mean(np.sum(error**2, axis=1))))


# --- predictions from the equations -------------------------------------------------


def predicted_centre_y_pct(settings: Any) -> tuple[float, float, float]:
    """Eq. (9)-(11) with the image centre's row as v0: each camera's y is off by
    ``(cy - v_centre) / ky`` of its depth, and y_h is their mean.  The two cameras'
    terms and y_h's, % of depth."""
    terms = []
    for camera in settings.cameras:
        pinhole = camera.pinhole()
        terms.append(100.0 * (pinhole.cy - pinhole.image_centre[1]) / pinhole.ky)
    return terms[0], terms[1], 0.5 * (terms[0] + terms[1])


def _forward_estimates(
    settings: Any, targets: np.ndarray, v0: tuple[float, float], alpha_e: tuple[float, float]
) -> np.ndarray:
    """Model 2's estimates (N, 3), m, from the exact forward model's images of ``targets``
    with reference rows ``v0`` and initial directions ``alpha_e`` (the servo on the
    image centre's column, exact eye angles)."""
    from headsim.estimators import model2
    from headsim.geometry.synthetic import observe
    from headsim.sim.forward import stereo_head

    head = stereo_head(settings)
    seen = observe(head, targets)
    u1 = head.cam1.image_centre[0]
    u2 = head.cam2.image_centre[0]
    estimate = model2(
        seen.alpha1,
        seen.alpha2,
        seen.uv1,
        seen.uv2,
        head.baseline,
        uv10=(u1, v0[0]),
        uv20=(u2, v0[1]),
        alpha_e=alpha_e,
        gamma1=seen.gamma1,
        gamma2=seen.gamma2,
    )
    return np.asarray(estimate.positions, dtype=float)


def predicted_forward(settings: Any, targets: np.ndarray) -> dict[str, Any]:
    """The same equations on the exact forward model's images of ``targets``: the y error
    the image centre's row adds (% of depth, per target), and after the zoom x1.5 the
    x/z error of a kept calibration (its initial directions as found at x1.0, exact)
    and each eye's shift of the effective initial direction, rad."""
    from headsim.active.principal import zoomed
    from headsim.sim.forward import effective_directions

    rows = tuple(c.pinhole().cy for c in settings.cameras)
    centre = tuple(c.pinhole().image_centre[1] for c in settings.cameras)
    kept = effective_directions(settings)
    known = _forward_estimates(settings, targets, (rows[0], rows[1]), kept)
    blind = _forward_estimates(settings, targets, (centre[0], centre[1]), kept)
    after = zoomed(settings, 1.5)
    moved = effective_directions(after)
    zoom_estimate = _forward_estimates(after, targets, (rows[0], rows[1]), kept)
    return {
        "centre_y_pct": 100.0 * (blind[:, 1] - known[:, 1]) / targets[:, 2],
        "zoom_xz_pct": xz_pct(targets, zoom_estimate - targets),
        "direction_shift_rad": (moved[0] - kept[0], moved[1] - kept[1]),
    }


# --- the findings -------------------------------------------------------------------


def _runs() -> list[dict[str, Any]]:
    return [tables_run(seed) for seed in SEEDS]


def _spread(values: list[float], digits: int = 3) -> str:
    return f"{median(values):.{digits}f} ({span(values, digits)})"


def _seed_text() -> str:
    return f"median over {seeds_label()} (min-max over the seeds)"


def findings_xz() -> str:
    """x and z without intrinsics: the three image-centre methods' x/z errors, against
    calibrated stereo's."""
    runs = _runs()
    centre, stereo, spread_between, targets = [], [], [], 0
    for run in runs:
        truth, error = _errors(run, 0, CENTRE)
        centre.append(_rms_pct(np.hypot(error[:, 0], error[:, 2]) / truth[:, 2]))
        truth_s, error_s = _errors(run, 0, STEREO)
        stereo.append(_rms_pct(np.hypot(error_s[:, 0], error_s[:, 2]) / truth_s[:, 2]))
        targets += len(truth)
        xz = {m: _errors(run, 0, m)[1][:, [0, 2]] for m in (CENTRE, V_KNOWN, EXTENDED)}
        spread_between.append(
            max(float(np.max(np.abs(xz[m] - xz[CENTRE]))) for m in (V_KNOWN, EXTENDED))
        )
    ratio = [c / s for c, s in zip(centre, stereo, strict=True)]
    most = max(spread_between)
    same = (
        "the same to the last bit for every target and seed"
        if most == 0.0
        else f"they differ by at most {1e3 * most:.1e} mm over every target and seed"
    )
    return (
        f"x/z error RMS, % of depth, {_seed_text()}, {targets} targets over "
        f"{len(runs)} seeds: the active method with the image centre as principal point "
        f"(Table VI, no intrinsics) **{_spread(centre)} %**, calibrated stereo (Zhang, "
        f"distortion modelled) {_spread(stereo)} %; active over stereo {_spread(ratio, 2)}. "
        f"Predicted from eqs. (4)-(5): x and z take no v0 and no kx/ky, so Table V's "
        f"method (v0 known), Table VI's and the extended calibration give the same x and z "
        f"from the same images; measured: {same}.\n"
    )


def findings_y() -> str:
    """y with the image centre as principal point: its error against eq. (9)'s prediction."""
    settings = _settings()
    runs = _runs()
    term1, term2, first_order = predicted_centre_y_pct(settings)
    forward = predicted_forward(settings, _errors(runs[0], 0, CENTRE)[0])
    measured, rms_y, ratio, targets = [], [], [], 0
    for run in runs:
        truth, centre = _errors(run, 0, CENTRE)
        _, known = _errors(run, 0, V_KNOWN)
        measured.append(float(np.mean(100.0 * (centre[:, 1] - known[:, 1]) / truth[:, 2])))
        rms_y.append(_rms_pct(centre[:, 1] / truth[:, 2]))
        _, stereo = _errors(run, 0, STEREO)
        ratio.append(_rms_3d_mm(centre) / _rms_3d_mm(stereo))
        targets += len(truth)
    cams = settings.cameras
    rows = " and ".join(
        f"{c.pinhole().cy:.1f} px against {c.pinhole().image_centre[1]:.1f} (ky {c.ky:.1f} px)"
        for c in cams
    )
    return (
        f"y error RMS with the image centre as principal point (Table VI), {_seed_text()}, "
        f"{targets} targets over {len(runs)} seeds: **{_spread(rms_y)} % of depth**; its 3-D "
        f"RMS over calibrated stereo's {_spread(ratio, 1)} (the paper: 'very close'). "
        f"Predicted from eq. (9)-(11): the true principal rows are {rows}, so each camera's "
        f"y is off by (cy - v_centre) / ky of the depth, {term1:+.3f} % and {term2:+.3f} %, "
        f"and y_h, their mean, by **{first_order:+.3f} % of depth**; the same equations on "
        f"the exact forward model's images of the targets: "
        f"{_spread(list(forward['centre_y_pct']))} % (median over the targets, their range). "
        f"Measured, the Table VI estimate minus Table V's (v0 known) from the same images, "
        f"mean over each seed's targets: **{_spread(measured)} %**; measured over predicted "
        f"(first order) {_spread([m / first_order for m in measured], 2)}.\n"
    )


def findings_zoom() -> str:
    """A calibration kept across the focal length x1.5: each method's RMS before and after
    and their ratio, and the kept Sec. V directions' x/z error against the forward model's."""
    from figures_common import table

    settings = _settings()
    runs = _runs()
    truth0 = _errors(runs[0], 0, CENTRE)[0]
    forward = predicted_forward(settings, truth0)
    methods = (STEREO, V_KNOWN, CENTRE, EXTENDED, FIXED)
    before: dict[str, list[float]] = {m: [] for m in methods}
    after: dict[str, list[float]] = {m: [] for m in methods}
    after_xz: list[float] = []
    targets = 0
    for run in runs:
        for method in methods:
            before[method].append(_rms_3d_mm(_errors(run, 0, method)[1]))
            after[method].append(_rms_3d_mm(_errors(run, 1, method)[1]))
        truth, error = _errors(run, 1, CENTRE)
        after_xz.append(_rms_pct(np.hypot(error[:, 0], error[:, 2]) / truth[:, 2]))
        targets += len(truth)
    ratios = {m: [a / b for a, b in zip(after[m], before[m], strict=True)] for m in methods}
    rows = [
        [f"`{m}`", _spread(before[m], 3), _spread(after[m], 2), _spread(ratios[m], 1)]
        for m in methods
    ]
    kept = (V_KNOWN, CENTRE, EXTENDED)
    largest = max(kept, key=lambda m: median(ratios[m]))
    smallest_before = min(kept, key=lambda m: median(before[m]))
    why = (
        f"The kept calibrations' ratios are largest for `{largest}`, the one whose error "
        "before was the smallest: after the zoom they err alike."
        if largest == smallest_before
        else f"The kept calibrations' ratios are largest for `{largest}`; the smallest error "
        f"before was `{smallest_before}`'s."
    )
    shift1, shift2 = forward["direction_shift_rad"]
    columns = " and ".join(
        f"{c.pinhole().image_centre[0] - c.pinhole().cx:+.1f} px" for c in settings.cameras
    )
    predicted = _rms_pct(forward["zoom_xz_pct"] / 100.0)
    return (
        f"3-D error RMS, mm, before and after the focal length x1.5, every calibration kept, "
        f"{_seed_text()}, {targets} targets over {len(runs)} seeds:\n\n"
        + table(("method", "before, mm", "after, mm", "after / before"), rows)
        + f"\nThe kept Sec. V calibrations (Tables V, VI, extended) all measure x and z "
        f"**{_spread(after_xz)} % of depth** off after the zoom. Predicted: the initial "
        f"direction Sec. V finds is the mount yaw plus the angle of the goal column's ray, "
        f"atan((u10 - cx) / kx); the image centre's column u10 lies {columns} off the "
        f"principal columns cx, so with kx x1.5 the directions move by {1e3 * shift1:+.2f} "
        f"and {1e3 * shift2:+.2f} mrad, and eqs. (4)-(5) with the kept directions on the "
        f"exact forward model's images give x/z **{predicted:.3f} % of depth** RMS. {why}\n"
    )


def figure(path: Path = FIGURE) -> Path:
    """The findings' PNG: the y error of Table VI against eq. (9), and the x/z error after
    the zoom against the forward model's, per seed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    settings = _settings()
    runs = _runs()
    truth0 = _errors(runs[0], 0, CENTRE)[0]
    forward = predicted_forward(settings, truth0)
    first_order = predicted_centre_y_pct(settings)[2]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    ax = axes[0]
    for k, run in enumerate(runs):
        truth, centre = _errors(run, 0, CENTRE)
        _, known = _errors(run, 0, V_KNOWN)
        ax.plot(
            truth[:, 2],
            100.0 * (centre[:, 1] - known[:, 1]) / truth[:, 2],
            "o",
            alpha=0.6,
            label="measured, Table VI minus Table V" if k == 0 else None,
        )
    ax.plot(truth0[:, 2], forward["centre_y_pct"], "kx", ms=9, label="forward model, eqs. (9)-(11)")
    ax.axhline(first_order, color="grey", ls="--", label="eq. (9), first order")
    ax.set_xlabel("target depth, m")
    ax.set_ylabel("y error from v0 = image centre, % of depth")
    ax.set_title("y with the image centre as principal point")
    ax.legend(fontsize=8)
    ax = axes[1]
    for k, run in enumerate(runs):
        truth, error = _errors(run, 1, CENTRE)
        ax.plot(
            truth[:, 2],
            xz_pct(truth, error),
            "o",
            alpha=0.6,
            label="measured, Sec. V calibration kept" if k == 0 else None,
        )
        truth_f, error_f = _errors(run, 1, FIXED)
        ax.plot(
            truth_f[:, 2],
            xz_pct(truth_f, error_f),
            "s",
            color="tab:green",
            alpha=0.6,
            label="measured, zoom fixed point" if k == 0 else None,
        )
    ax.plot(truth0[:, 2], forward["zoom_xz_pct"], "kx", ms=9, label="forward model, eqs. (4)-(5)")
    ax.set_yscale("log")
    ax.set_xlabel("target depth, m")
    ax.set_ylabel("x/z error after focal length x1.5, % of depth")
    ax.set_title("a calibration kept across a change of focal length")
    ax.legend(fontsize=8)
    fig.suptitle(f"headsim's findings on the paper's claims (paper preset, {seeds_label()})")
    fig.tight_layout()
    fig.savefig(path, dpi=100, metadata={"Software": None})
    plt.close(fig)
    return path


def findings_figure() -> str:
    """The figure's line; with ``--write`` the PNG is drawn again."""
    if writing():
        figure()
    rel = FIGURE.relative_to(ROOT / "docs")
    return (
        f"![y with the image centre; x/z after the focal length x1.5]({rel})\n\n"
        f"`python tools/readme_figures.py --only findings_figure --write` draws it "
        f"({seeds_label()}, each seed's own calibration draw; every point a target).\n"
    )
