"""Issue 10's "done when" figures that the exact forward model can give, in seconds.

Run: .venv/bin/python benchmarks/realistic_head.py [--seeds 50]

Everything here is the exact synthetic model (headsim.geometry.synthetic) with the
realistic preset's tolerances (headsim.sim.tolerances.REALISTIC_BUDGET): the paper's
cameras (intrinsics, distortion, initial directions), optical centres 20 mm
forward and 1 / -0.5 mm sideways, a baseline 0.3 mm longer than believed,
encoder readings with the true angle anywhere within the count, a 1 mm
(Gaussian, per coordinate) tape measure.  Not here: rendering and centroid
noise, the servo, backlash and axis tilt (the rendered scenarios measure
those).  Whole shared field: |x/z| <= 0.15, |y/z| <= 0.1, 0.3-1.5 m.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from headsim.estimators import model2
from headsim.estimators.calibration import calibrate_initial_directions, calibrate_lines_of_sight
from headsim.files import write_csv_atomic
from headsim.geometry.camera_model import PinholeCamera
from headsim.geometry.synthetic import StereoHead, observe, quantise
from headsim.paper import INITIAL_DIRECTIONS_RAD as PAPER_INITIAL_DIRECTIONS
from headsim.paper import INTRINSICS as PAPER_INTRINSICS
from headsim.scenario.calibration_design import near_far_depths, offset_std_limit
from headsim.sim.tolerances import REALISTIC_BUDGET
from headsim.studies.plots import plot_budget

BELIEVED_D = 0.150
BANDS = ((0.3, 0.6), (0.6, 1.0), (1.0, 1.5))


def paper_cameras(distorted: bool = True) -> tuple[PinholeCamera, PinholeCamera]:
    cams = []
    for intr in PAPER_INTRINSICS:
        k1 = intr["k1"] if distorted else 0.0
        cams.append(
            PinholeCamera(640, 480, intr["kx"], intr["ky"], intr["cx"], intr["cy"], k1, 0.0)
        )
    return cams[0], cams[1]


def realistic(distorted: bool = True) -> StereoHead:
    b = REALISTIC_BUDGET
    c1, c2 = paper_cameras(distorted)
    return StereoHead(
        BELIEVED_D + b["baseline_error_m"][0],
        c1,
        c2,
        PAPER_INITIAL_DIRECTIONS[0],
        PAPER_INITIAL_DIRECTIONS[1],
        nodal1=b["nodal_offset_m"][0],
        nodal2=b["nodal_offset_m"][0],
        side1=b["side_offset_m"][0],
        side2=-0.5 * b["side_offset_m"][0],
    )


def field(rng: np.random.Generator, n: int, depth=(0.3, 1.5), lateral=0.15, vertical=0.1):
    z = rng.uniform(*depth, n)
    return np.column_stack(
        [rng.uniform(-lateral, lateral, n) * z, rng.uniform(-vertical, vertical, n) * z, z]
    )


def measure(head: StereoHead, p: np.ndarray, alpha_e, offsets, baseline: float) -> np.ndarray:
    """Model 2 from encoder readings (true angle anywhere within the count) and exact pixels."""
    obs = observe(head, p, gamma1=0.0, gamma2=0.0)
    a1, a2 = (
        quantise(obs.alpha1, head.encoder_resolution),
        quantise(obs.alpha2, head.encoder_resolution),
    )
    (u10, u20), cams = head.target_columns, (head.cam1, head.cam2)
    est = model2(a1, a2, obs.uv1, obs.uv2, baseline, uv10=(u10, cams[0].cy), uv20=(u20, cams[1].cy),
                 alpha_e=alpha_e, gamma1=0.0, gamma2=0.0,
                 kx_over_ky=(cams[0].kx / cams[0].ky, cams[1].kx / cams[1].ky),
                 los_offset_m=offsets)  # fmt: skip
    return est.positions


def pct(err: np.ndarray, p: np.ndarray) -> float:
    return float(100 * np.sqrt(np.nanmean(np.sum(err**2, axis=1) / p[:, 2] ** 2)))


CALIBRATION_DEPTH_M = (0.25, 1.5)


def calibrate(
    head: StereoHead, seed: int, n: int = 60, noise: float = 1e-3, layout: str = "uniform"
):
    """The extended fit from ``n`` balls; ``layout`` as ``[experiment.calibration] layout``."""
    rng = np.random.default_rng(seed)
    p = field(rng, n, depth=CALIBRATION_DEPTH_M, lateral=0.16, vertical=0.08)
    if layout == "near_far":  # the same x/z and y/z, at the design's two ranges
        p *= (near_far_depths(n, CALIBRATION_DEPTH_M) / p[:, 2])[:, None]
    obs = observe(head, p)
    a1, a2 = (
        quantise(obs.alpha1, head.encoder_resolution),
        quantise(obs.alpha2, head.encoder_resolution),
    )
    measured = p + rng.normal(0.0, noise, p.shape)
    return calibrate_lines_of_sight(a1, a2, measured, BELIEVED_D, sigma_position=noise,
                                    sigma_encoder=head.encoder_resolution / math.sqrt(12))  # fmt: skip


def _head(offsets: bool = True, baseline_error: bool = True) -> StereoHead:
    h = realistic()
    return replace(
        h,
        baseline=h.baseline if baseline_error else BELIEVED_D,
        nodal1=h.nodal1 if offsets else 0.0,
        nodal2=h.nodal2 if offsets else 0.0,
        side1=h.side1 if offsets else 0.0,
        side2=h.side2 if offsets else 0.0,
    )


def _condition(
    name: str, p: np.ndarray, seeds: int, *, offsets=True, baseline_error=True, count=True,
    tape=1e-3, extended=True, correct=True,
) -> dict[str, float | str]:  # fmt: skip
    """Median over calibrations of the whole-field errors, beside eqs. 15-18's first-order depth error."""
    head = _head(offsets, baseline_error)
    if not count:
        head = replace(head, encoder_resolution=1e-9)
    res = head.encoder_resolution
    rows, predicted = [], []
    obs = observe(head, p)
    a_sum = obs.alpha1 + obs.alpha2 + sum(head.effective_initial_directions())  # a1 + a2, rad
    for seed in range(seeds):
        rng = np.random.default_rng(3000 + seed)
        c = field(rng, 60, depth=(0.25, 1.5), lateral=0.16, vertical=0.08)
        o = observe(head, c)
        a1, a2 = quantise(o.alpha1, res), quantise(o.alpha2, res)
        measured = c + rng.normal(0.0, tape, c.shape) if tape > 0 else c
        if extended:
            fit = calibrate_lines_of_sight(a1, a2, measured, BELIEVED_D, sigma_position=max(tape, 1e-5),
                                           sigma_encoder=res / math.sqrt(12))  # fmt: skip
            alpha_e, offs = tuple(fit.alpha_e), tuple(fit.offset_m) if correct else (0.0, 0.0)
            cov = fit.covariance
            # Eqs. 15/17 to first order: dz/z = dD/D - d(a1 + a2)/(a1 + a2), here from the
            # calibration's errors (covariance) and the truth's offsets left uncorrected.
            var_sum = cov[0, 0] + cov[1, 1] + 2 * cov[0, 1]
            var_d = cov[2, 2] + cov[3, 3] - 2 * cov[2, 3]
        else:
            sec5 = calibrate_initial_directions(a1, a2, measured[:, 2], BELIEVED_D)
            alpha_e, offs = tuple(sec5.alpha_e), (0.0, 0.0)
            var_sum = float(np.sum(sec5.covariance))
            var_d = 0.0
        err = measure(head, p, alpha_e, offs, BELIEVED_D) - p
        z_pct = float(100 * np.sqrt(np.nanmean((err[:, 2] / p[:, 2]) ** 2)))
        rows.append((pct(err, p), z_pct))
        s1, s2 = head.line_of_sight_offsets()
        bias = (
            0.0 if (extended and correct) else (head.baseline - s1 + s2 - BELIEVED_D) / BELIEVED_D
        )
        quant = (res / math.sqrt(6)) ** 2 if count else 0.0  # two readings, each uniform in a count
        dz = np.sqrt(bias**2 + var_d / BELIEVED_D**2 + (var_sum + quant) / a_sum**2)
        predicted.append(float(100 * np.sqrt(np.mean(dz**2))))
    rows_a = np.array(rows)
    return {
        "condition": name,
        "rms_3d_pct": float(np.median(rows_a[:, 0])),
        "rms_depth_pct": float(np.median(rows_a[:, 1])),
        "predicted_depth_pct": float(np.median(predicted)),
    }


def budget_conditions(p: np.ndarray, seeds: int) -> list[dict[str, float | str]]:
    """The error budget: the realistic head, each imperfection off in turn, each extension on/off."""
    return [
        _condition("realistic, all on", p, seeds),
        _condition("  optical-centre offsets off", p, seeds, offsets=False),
        _condition("  baseline error off", p, seeds, baseline_error=False),
        _condition("  count error off", p, seeds, count=False),
        _condition("  tape noise off", p, seeds, tape=0.0),
        _condition("  offsets not corrected", p, seeds, correct=False),
        _condition("  Sec. V only (no extension)", p, seeds, extended=False),
    ]


def budget(p: np.ndarray, seeds: int, out: Path | None) -> None:
    """Print the error budget (and write its CSV and chart into ``out``)."""
    conditions = budget_conditions(p, seeds)
    print(
        f"\n4. Error budget, whole field (median over {seeds} calibrations); predicted: eqs. 15-18 to first order"
    )
    print(f"   {'condition':32s} {'3-D RMS %':>10s} {'depth RMS %':>12s} {'eqs. 15-18 %':>13s}")
    for c in conditions:
        print(
            f"   {c['condition']:32s} {c['rms_3d_pct']:10.3f} {c['rms_depth_pct']:12.3f} {c['predicted_depth_pct']:13.3f}"
        )
    if out is None:
        return
    out.mkdir(parents=True, exist_ok=True)
    write_csv_atomic(out / "error_budget.csv", conditions)
    plot_budget(
        conditions,
        out / "error_budget.png",
        bars=(
            ("rms_3d_pct", "3-D RMS (measured)"),
            ("rms_depth_pct", "depth RMS (measured)"),
            ("predicted_depth_pct", "depth, eqs. 15-18"),
        ),
        title="Realistic head: error budget (exact forward model)",
    )
    print(f"   wrote {out / 'error_budget.csv'} and {out / 'error_budget.png'}")


def recovery_figures(head: StereoHead, seeds: int, layout: str) -> dict[str, Any]:
    """Section 3: the extended fit against the truth over ``seeds`` tape draws.

    Lengths in m; ``offsets`` holds s1's and s2's figures, ``directions`` alpha_e1's and
    alpha_e2's; ``limit_m`` is eq. (1)'s least standard error of an offset for the layout.
    """
    s_true = head.line_of_sight_offsets()
    half = (head.baseline - BELIEVED_D) / 2
    exact_e = head.effective_initial_directions()
    truth = np.r_[exact_e, s_true[0] - half, s_true[1] + half]
    truth_b = head.baseline - s_true[0] + s_true[1]
    ranges = (
        near_far_depths(60, CALIBRATION_DEPTH_M)
        if layout == "near_far"
        else np.random.default_rng(0).uniform(*CALIBRATION_DEPTH_M, 100_000)
    )
    est, std, be, bs = [], [], [], []
    for seed in range(seeds):
        fit = calibrate(head, 1000 + seed, layout=layout)
        est.append(np.r_[fit.alpha_e, fit.offset_m])
        std.append(fit.std_errors)
        be.append(fit.effective_baseline_m - truth_b)
        bs.append(fit.effective_baseline_std_m)
    est_a, std_a, be_a, bs_a = np.array(est), np.array(std), np.array(be), np.array(bs)
    err = est_a - truth
    z = err / std_a
    return {
        "layout": layout,
        "seeds": seeds,
        "near_balls": int(np.sum(ranges == CALIBRATION_DEPTH_M[0])) if layout == "near_far" else 0,
        "limit_m": offset_std_limit(ranges, 1e-3) * math.sqrt(len(ranges) / 60),
        "baseline": {
            "rms_m": float(np.sqrt(np.mean(be_a**2))),
            "max_m": float(np.max(np.abs(be_a))),
            "std_m": float(np.mean(bs_a)),
            "z_spread": float(np.std(be_a / bs_a)),
        },
        "offsets": [
            {
                "rms_m": float(np.sqrt(np.mean(err[:, k] ** 2))),
                "max_m": float(np.max(np.abs(err[:, k]))),
                "std_m": float(np.mean(std_a[:, k])),
                "z_spread": float(np.std(z[:, k])),
                "within_1_std_pct": float(100 * np.mean(np.abs(z[:, k]) < 1)),
            }
            for k in (2, 3)
        ],
        "directions": [
            {"rms_rad": float(np.sqrt(np.mean(err[:, k] ** 2))), "z_spread": float(np.std(z[:, k]))}
            for k in (0, 1)
        ],
    }


def recovery(head: StereoHead, seeds: int, layout: str) -> None:
    """Print section 3 (see :func:`recovery_figures`)."""
    f = recovery_figures(head, seeds, layout)
    print(
        f"\n3. Calibration recovery over {seeds} seeds (60 balls at 0.25-1.5 m, layout "
        f"{layout}, 1 mm tape), realistic head; offset limit of eq. (1): {1e3 * f['limit_m']:.3f} mm"
    )
    b = f["baseline"]
    print(f"   effective baseline error: RMS {1e3 * b['rms_m']:.3f} mm, max {1e3 * b['max_m']:.3f} mm; "
          f"stated std {1e3 * b['std_m']:.3f} mm, z-score spread {b['z_spread']:.2f}")  # fmt: skip
    for name, o in zip(("s1", "s2"), f["offsets"], strict=True):
        print(f"   {name} error: RMS {1e3 * o['rms_m']:.3f} mm, max {1e3 * o['max_m']:.3f} mm; "
              f"stated std {1e3 * o['std_m']:.3f} mm, z-score spread {o['z_spread']:.2f}, "
              f"within 1 stated std {o['within_1_std_pct']:.0f} % (68 % expected)")  # fmt: skip
    for name, d in zip(("alpha_e1", "alpha_e2"), f["directions"], strict=True):
        print(f"   {name} error RMS {d['rms_rad']:.2e} rad; z-score spread {d['z_spread']:.2f}")


def whole_field(p: np.ndarray, seeds: int) -> np.ndarray:
    """Section 1: (seeds, 4) 3-D error RMS, % of depth, over ``p`` and per band in BANDS,
    after each of ``seeds`` extended calibrations of the realistic head."""
    head = realistic()
    rows = []
    for seed in range(seeds):
        fit = calibrate(head, seed)
        err = measure(head, p, tuple(fit.alpha_e), tuple(fit.offset_m), BELIEVED_D) - p
        rows.append(
            [pct(err, p)]
            + [
                pct(err[(p[:, 2] >= lo) & (p[:, 2] < hi)], p[(p[:, 2] >= lo) & (p[:, 2] < hi)])
                for lo, hi in BANDS
            ]
        )
    return np.array(rows)


def uncorrected(p: np.ndarray) -> dict[str, dict[str, float]]:
    """Section 2: depth error RMS with the offsets left uncorrected (initial directions exact),
    beside eq. 15's first-order |dD_eff| / D, % (and ``s``, the offsets, m), per head."""
    out = {}
    for label, h in (
        (
            "n = 20 mm both, delta of the paper's cameras",
            StereoHead(
                BELIEVED_D,
                *paper_cameras(False),
                *PAPER_INITIAL_DIRECTIONS,
                nodal1=0.02,
                nodal2=0.02,
            ),
        ),
        (
            "e = 1 mm both eyes",
            StereoHead(
                BELIEVED_D, *paper_cameras(False), *PAPER_INITIAL_DIRECTIONS, side1=1e-3, side2=1e-3
            ),
        ),
        ("realistic (offsets and baseline error)", realistic(False)),
    ):
        s1, s2 = h.line_of_sight_offsets()
        err = measure(h, p, h.effective_initial_directions(), (0.0, 0.0), BELIEVED_D) - p
        out[label] = {
            "s1_m": s1,
            "s2_m": s2,
            "depth_pct": float(100 * np.sqrt(np.mean((err[:, 2] / p[:, 2]) ** 2))),
            "x_pct": float(100 * np.sqrt(np.mean((err[:, 0] / p[:, 2]) ** 2))),
            # dz/z = dD/D, eq. 15
            "predicted_pct": 100 * abs(h.baseline - s1 + s2 - BELIEVED_D) / BELIEVED_D,
        }
    return out


def principal_columns_change(p: np.ndarray) -> tuple[float, float]:
    """Largest change of any x, z estimate and of any y, m, that n = 20 mm alone makes with
    the goal columns at the principal points (initial directions exact, offsets uncorrected)."""
    c = paper_cameras(False)
    h0 = StereoHead(
        BELIEVED_D,
        *c,
        *PAPER_INITIAL_DIRECTIONS,
        u10=c[0].cx,
        u20=c[1].cx,
        nodal1=0.02,
        nodal2=0.02,
    )
    hp = StereoHead(BELIEVED_D, *c, *PAPER_INITIAL_DIRECTIONS, u10=c[0].cx, u20=c[1].cx)
    diff = np.abs(
        measure(h0, p, h0.effective_initial_directions(), (0.0, 0.0), BELIEVED_D)
        - measure(hp, p, hp.effective_initial_directions(), (0.0, 0.0), BELIEVED_D)
    )
    return float(np.nanmax(diff[:, [0, 2]])), float(np.nanmax(diff[:, 1]))


def targets() -> np.ndarray:
    """The whole shared field's 2000 targets (seeded), in H, m."""
    return field(np.random.default_rng(2026), 2000)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=50)
    parser.add_argument("--budget-seeds", type=int, default=10)
    parser.add_argument("--out", type=Path, default=None, help="write error_budget.csv/.png here")
    args = parser.parse_args()
    p = targets()

    print(
        "1. Realistic head, whole field (2000 targets), after the extended calibration (60 targets, 1 mm tape)"
    )
    rows = whole_field(p, args.seeds)
    print(f"   3-D error RMS, % of depth, median over {args.seeds} calibrations (95th percentile):")
    for k, name in enumerate(["all", *(f"{lo}-{hi} m" for lo, hi in BANDS)]):
        print(f"     {name:10s} {np.median(rows[:, k]):.3f} ({np.percentile(rows[:, k], 95):.3f})")

    print(
        "\n2. Offsets left uncorrected (initial directions exact; line-of-sight offsets taken as 0)"
    )
    for label, u in uncorrected(p).items():
        print(f"   {label}: s = ({u['s1_m'] * 1e3:.3f}, {u['s2_m'] * 1e3:.3f}) mm; depth error RMS "
              f"{u['depth_pct']:.3f} %, x {u['x_pct']:.3f} %, first-order |dD_eff|/D "
              f"{u['predicted_pct']:.3f} %")  # fmt: skip
    xz, y = principal_columns_change(p)
    print(
        "   goal columns at the principal points, n = 20 mm alone: largest change of any x, z "
        f"estimate {xz:.2e} m; of y {y:.2e} m "
        "(y: near-midline targets switch between one camera's y and the mean)"
    )

    head = realistic()
    for layout in ("uniform", "near_far"):
        recovery(head, args.seeds, layout)

    budget(p[:500], args.budget_seeds, args.out)


if __name__ == "__main__":
    main()
