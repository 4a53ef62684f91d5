"""Calibrated stereo on rendered views: Zhang calibration and 3-D errors beside the truth.

For the ideal and the paper presets: run ``scenarios/stereo.toml`` (the ``stereo``
procedure, :mod:`headsim.procedures.stereo`) with --poses board poses and --seed:
the chessboard in seeded poses at eye angle 0, each camera calibrated
(``calibrateCamera``, k1, k2) and the pair (``stereoCalibrate``); print the
reprojection RMS and the recovered parameters beside the simulator's, then the
scenario's markers at 0.4-1.5 m triangulated, with their 3-D errors in the head
frame H.  The acceptance figure: reprojection RMS <= 0.2 px and focal lengths within 0.5 %.

    python benchmarks/stereo_calibration.py [--poses 24] [--seed 0] [--json out.json]
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.codec import encode
from headsim.files import write_json_atomic
from headsim.procedures.stereo import FOCAL_BOUND, RMS_BOUND_PX, StereoResult
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario


def run_preset(name: str, poses: int, seed: int) -> dict[str, Any]:
    """The stereo scenario on the preset ``name``: its result block and run time, s."""
    scenario = load_scenario(
        "stereo", seed=seed, overrides={"head.preset": name, "experiment.stereo.views": poses}
    )
    start = time.perf_counter()
    result = run_scenario(scenario)
    seconds = time.perf_counter() - start
    assert isinstance(result.experiment, StereoResult)
    return {"preset": name, "run_s": seconds, **encode(result.experiment)}


def print_preset(r: dict[str, Any]) -> None:
    print(
        f"\n== {r['preset']}: {r['views']}/{r['poses']} views kept, {r['renders']} renders, "
        f"{r['run_s']:.1f} s (views, calibration and markers)"
    )
    print(
        f"corner detection vs truth: RMS {r['corner_rms_px']:.3f} px, max {r['corner_max_px']:.3f} px"
    )
    print(f"{'':8s} {'truth':>10s} {'mono':>10s} {'err':>9s} {'stereo':>10s} {'err':>9s}")
    for index, table in enumerate(r["cameras"]):
        print(f"camera {index + 1}")
        for param, row in table.items():
            t, m, s = row["truth"], row["mono"], row["stereo"]
            if param in ("kx", "ky"):
                unit = "%"
                em, es = (m / t - 1) * 100, (s / t - 1) * 100
            else:
                unit = " px" if param in ("cx", "cy") else ""
                em, es = m - t, s - t
            if param == "rms_px":
                print(f"  {'RMS px':8s} {'':>10s} {m:10.4f} {'':>9s} {s:10.4f}")
                continue
            print(
                f"  {param:8s} {t:10.4f} {m:10.4f} {em:+8.3f}{unit:2s} {s:10.4f} {es:+8.3f}{unit:2s}"
            )
    baseline, truth = r["baseline_m"] * 1e3, r["true_baseline_m"] * 1e3
    print(
        f"baseline {baseline:.3f} mm (truth {truth:.3f}, {baseline - truth:+.3f} mm); "
        f"R error {r['rotation_error_rad'] * 1e3:.3f} mrad"
    )
    fmt = {"float_kind": lambda x: f"{x:.3f}"}
    print(
        "T mm: estimate "
        + np.array2string(r["t_m"] * 1e3, formatter=fmt)
        + ", truth "
        + np.array2string(r["true_t_m"] * 1e3, formatter=fmt)
    )
    print(
        f"{'H built as':30s} {'rot mrad':>9s} {'trans mm':>9s} {'max mm':>8s} {'max %z':>7s} {'mean %z':>8s}"
    )
    for f in r["head_frames"]:
        print(
            f"  {f['label']:28s} {f['rotation_error_rad'] * 1e3:9.3f} "
            f"{f['translation_error_m'] * 1e3:9.4f} {f['max_error_m'] * 1e3:8.2f} "
            f"{f['max_error_pct_depth']:7.3f} {f['mean_error_pct_depth']:8.3f}"
        )
    print(
        "markers (H from extrinsics):   true (x, y, z) mm        error (x, y, z) mm      |e| mm  % z"
    )
    for m in r["targets"]:
        t = m["truth_head_m"] * 1e3
        if m["status"] != "ok":
            print(f"  ({t[0]:7.1f}, {t[1]:7.1f}, {t[2]:7.1f})  {m['status']}")
            continue
        e = m["estimate_head_m"] * 1e3 - t
        print(
            f"  ({t[0]:7.1f}, {t[1]:7.1f}, {t[2]:7.1f})  ({e[0]:+6.2f}, {e[1]:+6.2f}, {e[2]:+6.2f})"
            f"  {np.linalg.norm(e):6.2f}  {100 * np.linalg.norm(e) / t[2]:5.3f}"
        )
    print(
        f"done-when (RMS <= {RMS_BOUND_PX} px, focal within {FOCAL_BOUND * 100} %): "
        f"max RMS {r['max_rms_px']:.3f} px, max focal error {r['max_abs_focal_error_pct']:.3f} % -> "
        f"{'PASS' if r['passed'] else 'FAIL'}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=24, help="chessboard poses per preset")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the figures to this JSON file")
    args = parser.parse_args()
    results = {name: run_preset(name, args.poses, args.seed) for name in ("ideal", "paper")}
    for r in results.values():
        print_preset(r)
    if args.json:
        write_json_atomic(args.json, results)


if __name__ == "__main__":
    main()
