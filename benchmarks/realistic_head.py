"""Issue 10's "done when" figures that the exact forward model can give, in seconds.

Run: .venv/bin/python benchmarks/realistic_head.py [--seeds 50]

Everything here is the exact synthetic model (headsim.synthetic) with the
realistic preset's tolerances (headsim.settings.REALISTIC_BUDGET): the paper's
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

import numpy as np

from headsim.camera_model import PinholeCamera
from headsim.estimators import model2
from headsim.estimators.calibration import calibrate_lines_of_sight
from headsim.settings import PAPER_INITIAL_DIRECTIONS, PAPER_INTRINSICS, REALISTIC_BUDGET
from headsim.synthetic import StereoHead, observe, quantise

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


def calibrate(head: StereoHead, seed: int, n: int = 60, noise: float = 1e-3):
    rng = np.random.default_rng(seed)
    p = field(rng, n, depth=(0.25, 1.5), lateral=0.16, vertical=0.08)
    obs = observe(head, p)
    a1, a2 = (
        quantise(obs.alpha1, head.encoder_resolution),
        quantise(obs.alpha2, head.encoder_resolution),
    )
    measured = p + rng.normal(0.0, noise, p.shape)
    return calibrate_lines_of_sight(a1, a2, measured, BELIEVED_D, sigma_position=noise,
                                    sigma_encoder=head.encoder_resolution / math.sqrt(12))  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=50)
    args = parser.parse_args()
    rng = np.random.default_rng(2026)
    p = field(rng, 2000)

    print(
        "1. Realistic head, whole field (2000 targets), after the extended calibration (60 targets, 1 mm tape)"
    )
    head = realistic()
    rows = []
    for seed in range(args.seeds):
        fit = calibrate(head, seed)
        err = measure(head, p, tuple(fit.alpha_e), tuple(fit.offset_m), BELIEVED_D) - p
        rows.append(
            [pct(err, p)]
            + [
                pct(err[(p[:, 2] >= lo) & (p[:, 2] < hi)], p[(p[:, 2] >= lo) & (p[:, 2] < hi)])
                for lo, hi in BANDS
            ]
        )
    rows = np.array(rows)
    print(f"   3-D error RMS, % of depth, median over {args.seeds} calibrations (95th percentile):")
    for k, name in enumerate(["all", *(f"{lo}-{hi} m" for lo, hi in BANDS)]):
        print(f"     {name:10s} {np.median(rows[:, k]):.3f} ({np.percentile(rows[:, k], 95):.3f})")

    print(
        "\n2. Offsets left uncorrected (initial directions exact; line-of-sight offsets taken as 0)"
    )
    s_true = head.line_of_sight_offsets()
    half = (head.baseline - BELIEVED_D) / 2
    exact_e = head.effective_initial_directions()
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
        dz = float(100 * np.sqrt(np.mean((err[:, 2] / p[:, 2]) ** 2)))
        predicted = 100 * abs(h.baseline - s1 + s2 - BELIEVED_D) / BELIEVED_D  # dz/z = dD/D, eq. 15
        print(f"   {label}: s = ({s1 * 1e3:.3f}, {s2 * 1e3:.3f}) mm; depth error RMS {dz:.3f} %, "
              f"first-order |dD_eff|/D {predicted:.3f} %, ratio {dz / predicted:.3f}")  # fmt: skip
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
    print(
        "   goal columns at the principal points, n = 20 mm alone: largest change of any x, z "
        f"estimate {np.nanmax(diff[:, [0, 2]]):.2e} m; of y {np.nanmax(diff[:, 1]):.2e} m "
        "(y: near-midline targets switch between one camera's y and the mean)"
    )

    print(
        f"\n3. Calibration recovery over {args.seeds} seeds (60 targets at 0.25-1.5 m, 1 mm tape), realistic head"
    )
    truth = np.r_[exact_e, s_true[0] - half, s_true[1] + half]
    truth_b = head.baseline - s_true[0] + s_true[1]
    est, std, be, bs = [], [], [], []
    for seed in range(args.seeds):
        fit = calibrate(head, 1000 + seed)
        est.append(np.r_[fit.alpha_e, fit.offset_m])
        std.append(fit.std_errors)
        be.append(fit.effective_baseline_m - truth_b)
        bs.append(fit.effective_baseline_std_m)
    est, std, be, bs = np.array(est), np.array(std), np.array(be), np.array(bs)
    err = est - truth
    print(f"   effective baseline error: RMS {1e3 * np.sqrt(np.mean(be**2)):.3f} mm, max {1e3 * np.max(np.abs(be)):.3f} mm; "
          f"stated std {1e3 * np.mean(bs):.3f} mm, z-score spread {np.std(be / bs):.2f}")  # fmt: skip
    for k, name in ((2, "s1"), (3, "s2")):
        print(f"   {name} error: RMS {1e3 * np.sqrt(np.mean(err[:, k] ** 2)):.3f} mm, max {1e3 * np.max(np.abs(err[:, k])):.3f} mm; "
              f"stated std {1e3 * np.mean(std[:, k]):.3f} mm, z-score spread {np.std(err[:, k] / std[:, k]):.2f}")  # fmt: skip
    for k, name in ((0, "alpha_e1"), (1, "alpha_e2")):
        print(
            f"   {name} error RMS {np.sqrt(np.mean(err[:, k] ** 2)):.2e} rad; z-score spread {np.std(err[:, k] / std[:, k]):.2f}"
        )


if __name__ == "__main__":
    main()
