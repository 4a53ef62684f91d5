"""Accuracy and effort of the paper's procedures in the simulator, on seeded random targets.

Prints, per camera preset: 3-D error (RMS, mm and % of depth, per depth band),
renders per measured point, servo residuals, wall time per point and its ratio
to one render; for the paper's cameras the Sec. V calibration against the
truth, the y error under three conditions and an error budget with each
imperfection switched off; the chessboard's squares; relative-positioning
areas; servo robustness to untold focal lengths and principal points; and
tracking with the neck.  Figures, not a test.

    python benchmarks/procedures_accuracy.py [--fast] [--seed 0] [--json out.json]
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.active.measurement import HeadKnowledge
from headsim.files import write_json_atomic
from headsim.runs.progress import Status
from headsim.sim.settings import HeadSettings, paper_head
from headsim.studies import experiments

#: Each experiment's steps on stderr: one redrawn line on a terminal, plain lines in a log.
progress = Status("procedures_accuracy", transient=True)


def done() -> None:
    progress.close()


def fmt(value: Any, digits: int = 3) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    if isinstance(value, list):
        return "(" + ", ".join(fmt(v, digits) for v in value) + ")"
    return str(value)


def print_accuracy(title: str, fig: dict[str, Any]) -> None:
    print(f"\n== {title}")
    if "calibration" in fig:
        c = fig["calibration"]
        print(
            f"Sec. V calibration ({c['samples']} targets, {c['renders']} renders): "
            f"alpha_e {fmt(c['alpha_e_rad'], 5)} rad, truth {fmt(c['truth_alpha_e_rad'], 5)}, "
            f"error {fmt([e * 1e4 for e in c['error_rad']], 2)} e-4 rad "
            f"(reported std {fmt([e * 1e4 for e in c['std_error_rad']], 2)} e-4)"
        )
        if c["v0_px"]:
            print(f"extended: v0 {fmt(c['v0_px'], 2)} px, kx/ky {fmt(c['kx_over_ky'], 4)}")
    print(
        f"{'targets':24s} {'n':>4s} {'3-D mm':>8s} {'3-D %z':>8s} {'x %z':>7s} {'y %z':>7s} {'z %z':>7s} {'max %z':>7s}"
    )
    rows = [*fig["bands"].items(), ("all 0.3-1.5 m", fig["overall"])]
    if "near_centre_row" in fig:
        rows.append(
            (
                f"within {experiments.CENTRE_ROW_BAND_PX:.0f} px of centre row",
                fig["near_centre_row"],
            )
        )
    for key, f in rows:
        if not f.get("count"):
            print(f"{key:24s} {0:4d}")
            continue
        x, y, z = f["rms_pct_depth_xyz"]
        print(
            f"{key:24s} {f['count']:4d} {f['rms_3d_mm']:8.2f} {f['rms_3d_pct_depth']:8.3f} "
            f"{x:7.3f} {y:7.3f} {z:7.3f} {f['max_3d_pct_depth']:7.3f}"
            + (f"  ({f['failed']} failed)" if f["failed"] else "")
        )
    print(
        f"renders per point (after the first): {fmt(fig['renders_per_point_after_first'], 2)}; "
        f"servo residual mean {fmt(fig['servo_residual_px_mean'])} px, max {fmt(fig['servo_residual_px_max'])} px"
    )
    print(
        f"wall time per point {1000 * fig['wall_s_per_point']:.1f} ms = "
        f"{fig['wall_per_point_over_render']:.1f} renders ({1000 * fig['render_s']:.1f} ms each)"
    )
    if "y_conditions" in fig:
        print("y error RMS (% of depth) by what the head knows:")
        for key, f in fig["y_conditions"].items():
            print(f"  {key:34s} {f['rms_pct_depth_xyz'][1]:7.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fast", action="store_true", help="fewer targets (a minute or so)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the figures to this JSON file")
    args = parser.parse_args()
    per_band = 6 if args.fast else 20
    cal_targets = 30 if args.fast else 60
    start = time.perf_counter()
    figures: dict[str, Any] = {"seed": args.seed, "fast": args.fast}

    figures["ideal"] = experiments.model2_accuracy(
        HeadSettings(),
        np.random.default_rng(args.seed),
        targets_per_band=per_band,
        progress=progress,
    )
    done()
    print_accuracy("ideal cameras, Model 2, no calibration", figures["ideal"])

    figures["paper"] = experiments.model2_accuracy(
        paper_head(),
        np.random.default_rng(args.seed),
        targets_per_band=per_band,
        calibrate=True,
        calibration_targets=cal_targets,
        progress=progress,
    )
    done()
    print_accuracy(
        "paper's cameras, Model 2 after Sec. V calibration (no intrinsics)", figures["paper"]
    )

    figures["error_budget"] = experiments.paper_error_budget(
        args.seed,
        targets_per_band=max(per_band // 2, 4),
        calibration_targets=cal_targets,
        progress=progress,
    )
    done()
    print("\n== error budget, paper's cameras (x and z RMS, % of depth)")
    print(f"{'':28s} {'near centre row':>20s} {'whole image':>20s} {'calib err e-4 rad':>20s}")
    for label, f in figures["error_budget"].items():
        near, whole = f["near_centre_row"], f["overall"]
        near_xz = (
            fmt([near["rms_pct_depth_xyz"][0], near["rms_pct_depth_xyz"][2]])
            if near.get("count")
            else "-"
        )
        whole_xz = fmt([whole["rms_pct_depth_xyz"][0], whole["rms_pct_depth_xyz"][2]])
        cal = fmt([e * 1e4 for e in f["calibration_error_rad"]], 2)
        print(f"{label:28s} {near_xz:>20s} {whole_xz:>20s} {cal:>20s}")

    paper_cal = figures["paper"]["calibration"]
    knowledge = HeadKnowledge(
        alpha_e=tuple(paper_cal["alpha_e_rad"]),
        v0=tuple(paper_cal["v0_px"]),
        kx_over_ky=tuple(paper_cal["kx_over_ky"]),
    )
    corners = [9, 10, 11, 12, 17, 18, 19, 20] if args.fast else None
    figures["chessboard"] = experiments.chessboard_accuracy(
        paper_head(), knowledge, corners=corners
    )
    print(
        "\n== chessboard, 30 mm squares at 0.85 m, paper's cameras (paper: 30.3 mm mean, 0.677 mm std)"
    )
    for label, f in figures["chessboard"].items():
        print(
            f"{label:22s} corners {f['corners_measured']}/{f['corners']}: "
            f"width {fmt(f['width_mean_mm'])} +- {fmt(f['width_std_mm'])} mm, "
            f"height {fmt(f['height_mean_mm'])} +- {fmt(f['height_std_mm'])} mm"
        )

    figures["relative"] = experiments.relative_areas(
        np.random.default_rng(args.seed), layouts=3 if args.fast else 9, progress=progress
    )
    done()
    r = figures["relative"]
    print(
        f"\n== relative positioning: {r['objects']} objects, {fmt(r['correct_pct'], 1)} % of all in "
        f"their true area; {r['outside_margin']} more than 2 px from a "
        f"boundary, {fmt(r['outside_margin_correct_pct'], 1)} % of them in their true area; "
        f"{r['within_2px_of_a_boundary']} within 2 px ({r['within_2px_disagreeing']} disagreeing); "
        f"{r['not_seen_in_all_four_images']} not in all four images; true areas seen {r['distinct_true_areas']}"
    )

    figures["servo"] = experiments.servo_robustness(
        np.random.default_rng(args.seed), points=4 if args.fast else 8, progress=progress
    )
    done()
    print(
        "\n== servo told nothing about the camera (Model 2, both steps, both cameras; 3-D error uncalibrated)"
    )
    print(
        f"{'camera':18s} {'converged':>9s} {'renders/pt':>10s} {'resid mean':>10s} {'resid max':>9s} {'half step':>9s} {'3-D %z':>7s}"
    )
    for label, f in figures["servo"].items():
        print(
            f"{label:18s} {f['converged']:>9s} {fmt(f['renders_per_point_after_first'], 2):>10s} "
            f"{fmt(f['residual_px_mean']):>10s} {fmt(f['residual_px_max']):>9s} {fmt(f['half_step_px']):>9s} "
            f"{fmt(f['rms_3d_pct_depth']):>7s}"
        )

    figures["tracking"] = experiments.tracking_accuracy(fixations=6 if args.fast else 12)
    t = figures["tracking"]
    print(
        f"\n== tracking with the neck (Model 1): {t['ok']}/{t['fixations']} fixations, world error RMS "
        f"{t['error_world_mm_rms']:.2f} mm (max {t['error_world_mm_max']:.2f}), renders {t['renders_first']} "
        f"for the first, {t['renders_per_fixation_after_first']:.1f} after"
    )
    figures["wall_s"] = time.perf_counter() - start
    print(f"\ntotal wall time {figures['wall_s']:.0f} s")
    if args.json:
        write_json_atomic(args.json, figures)


if __name__ == "__main__":
    main()
