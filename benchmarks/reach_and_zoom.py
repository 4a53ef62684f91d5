"""Every target the reach check accepts gets measured, across zoom (issue 11's figures).

Per focal length (0.5x, 0.7x, 1x, 1.3x, 1.6x, 2x the paper's, mounts unchanged):
calibrate (Sec. V, the layout's every position recorded), then draw random
targets over the whole field in front of the head, let the scenario's reach
check accept or refuse each (with its reason), and measure every accepted one
with Model 2 and Model 1 (the neck left where the last target was).  Prints
per zoom and model: accepted, measured, failures by cause, 3-D error RMS
(mm, % of depth) and its ratio to 1x, renders per point over all targets and
without the ones that needed a search, and the search's extra renders.
Figures, not a test.

    python benchmarks/reach_and_zoom.py [--per-zoom 40] [--calibration 20] [--zooms 0.7,1,2]
                                        [--goal centre|fixed-point] [--seed 0] [--json F]
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from dataclasses import replace
from typing import Any

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim import names
from headsim.principal import principal_points_by_zoom
from headsim.procedures import (
    CalibrationError,
    HeadKnowledge,
    Measurement,
    calibrate_head,
    calibration_layout,
    measure_model1,
    measure_model2,
)
from headsim.results import write_json_atomic
from headsim.runner import marker_target
from headsim.scenario import _Head, model1_refusal, model2_refusal
from headsim.servo import EyeServo, NeckServo
from headsim.settings import HeadSettings, paper_head
from headsim.sim import HeadSim

ZOOMS = (0.5, 0.7, 1.0, 1.3, 1.6, 2.0)
BODY = names.MARKERS[0]
#: The field targets are drawn from, in H at the start pose: depth m, |x/z|, |y/z|.
FIELD = {"depth_m": (0.4, 1.4), "lateral": 0.3, "vertical": 0.15}


def zoomed(zoom: float, seed: int) -> HeadSettings:
    """The paper's head with both focal lengths times ``zoom`` (mounts as at 1x)."""
    base = paper_head(seed=seed)
    cams = tuple(replace(c, kx=c.kx * zoom, ky=c.ky * zoom) for c in base.cameras)
    return replace(base, cameras=cams)  # type: ignore[arg-type]


def draw_targets(
    settings: HeadSettings, rng: np.random.Generator, count: int
) -> tuple[list[np.ndarray], Counter[str]]:
    """``count`` accepted world points (both models' checks), and the refusals' reasons."""
    head = _Head.of(settings)
    accepted: list[np.ndarray] = []
    refused: Counter[str] = Counter()
    radius = 0.004
    for _ in range(count * 50):
        if len(accepted) == count:
            break
        z = rng.uniform(*FIELD["depth_m"])
        p_head = np.array(
            [
                rng.uniform(-FIELD["lateral"], FIELD["lateral"]) * z,
                rng.uniform(-FIELD["vertical"], FIELD["vertical"]) * z,
                z,
            ]
        )
        p_world = _head_to_world(settings, p_head)
        refusal = model2_refusal(head, p_world, "target", radius) or model1_refusal(
            head, p_world, "target", True, radius
        )
        if refusal is None:
            accepted.append(p_world)
        else:
            refused[refusal[0].split(" is ")[-1].split(" needs ")[-1][:48]] += 1
    return accepted, refused


def _head_to_world(settings: HeadSettings, p_head: np.ndarray) -> np.ndarray:
    from headsim.kinematics import head_to_world

    return head_to_world(p_head, 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)


def stats(ms: list[Measurement]) -> dict[str, Any]:
    ok = [m for m in ms if m.ok]
    errors = np.array([np.linalg.norm(m.error_head_m) for m in ok])
    pct = np.array([m.error_pct_of_depth for m in ok])
    searched = [m for m in ms if m.search_renders > 0]
    plain = [m for m in ms if m.search_renders == 0]
    return {
        "targets": len(ms),
        "measured": len(ok),
        "failures": dict(Counter(m.failure.message for m in ms if m.failure is not None)),
        "lost": sum(m.failure is not None and m.failure.cause.value == "lost" for m in ms),
        "error_rms_mm": float(np.sqrt(np.mean(errors**2)) * 1e3) if ok else None,
        "error_rms_pct": float(np.sqrt(np.mean(pct**2))) if ok else None,
        "renders_per_point": float(np.mean([m.renders for m in ms])) if ms else None,
        "renders_per_point_without_searched": float(np.mean([m.renders for m in plain]))
        if plain
        else None,
        "searched": len(searched),
        "search_renders_mean": float(np.mean([m.search_renders for m in searched]))
        if searched
        else 0.0,
    }


def run_zoom(zoom: float, per_zoom: int, calibration: int, seed: int, goal: str) -> dict[str, Any]:
    settings = zoomed(zoom, seed)
    rng = np.random.default_rng([seed, int(zoom * 100)])
    targets, refused = draw_targets(settings, rng, per_zoom)
    out: dict[str, Any] = {"zoom": zoom, "accepted": len(targets), "refused": dict(refused)}
    base = HeadKnowledge()
    if goal == "fixed-point":
        # The goal columns through each camera's zoom fixed point, from images alone.
        found = principal_points_by_zoom(settings, rng=np.random.default_rng(seed))
        base = HeadKnowledge(u0=(found.principal_px[0][0], found.principal_px[1][0]))
        out["goal_columns_px"] = [base.u0[0], base.u0[1]]
        out["goal_column_error_px"] = [float(e) for e in found.errors_px[:, 0]]
    with HeadSim("default", settings) as sim:
        servo = EyeServo(sim)
        ball = marker_target(names.CALIBRATION_BALL, names.CALIBRATION_BALL)
        positions = calibration_layout(sim, rng, calibration)
        try:
            run = calibrate_head(
                sim, servo, ball, names.CALIBRATION_BALL, positions, knowledge=base
            )
            knowledge = run.knowledge
            outcomes = run.outcomes
            out["calibration"] = {
                "positions": len(outcomes),
                "fixated": sum(o is None for o in outcomes),
                "not_fixated": dict(Counter(o.message for o in outcomes if o is not None)),
                "alpha_e_error_rad": [float(x) for x in run.alpha_e_error],
            }
        except CalibrationError as err:
            out["calibration"] = {"failed": str(err), "positions": len(err.outcomes)}
            out["calibration"]["fixated"] = sum(o is None for o in err.outcomes)
            return out
        m2 = []
        for k, p in enumerate(targets):
            sim.set_body_pose(BODY, p)
            m2.append(measure_model2(sim, servo, marker_target(f"t{k}", BODY), knowledge))
        sim.command(neck_yaw=0.0, neck_pitch=0.0, eye=0.0)
        sim.settle()
        neck = NeckServo(sim)
        m1 = []
        for k, p in enumerate(targets):
            sim.set_body_pose(BODY, p)
            m1.append(measure_model1(sim, neck, marker_target(f"t{k}", BODY), knowledge))
    out["model2"], out["model1"] = stats(m2), stats(m1)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-zoom", type=int, default=40, help="accepted targets per zoom")
    parser.add_argument("--calibration", type=int, default=20, help="calibration positions")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--goal",
        choices=("centre", "fixed-point"),
        default="centre",
        help="servo goal columns: the image centre's, or each zoom's fixed point",
    )
    parser.add_argument("--zooms", help="comma-separated focal factors (default 0.5,...,2)")
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()
    start = time.perf_counter()
    rows = []
    zooms = [float(z) for z in args.zooms.split(",")] if args.zooms else ZOOMS
    for zoom in zooms:
        print(f"  zoom {zoom}x ...", file=sys.stderr, flush=True)
        rows.append(run_zoom(zoom, args.per_zoom, args.calibration, args.seed, args.goal))
    one = [r for r in rows if r["zoom"] == 1.0]
    base = {m: one[0].get(m, {}) if one else {} for m in ("model2", "model1")}
    print(
        f"Field: depth {FIELD['depth_m']} m, |x/z| <= {FIELD['lateral']}, "
        f"|y/z| <= {FIELD['vertical']}; paper's cameras, focal x zoom; goal columns: {args.goal}"
    )
    print(
        f"{'zoom':>5} {'model':>6} {'acc':>4} {'ok':>4} {'lost':>4} {'rms mm':>8} {'rms %':>7} "
        f"{'x 1x':>5} {'r/pt':>5} {'r/pt-s':>6} {'srch':>4} {'+r':>4}  failures"
    )
    for r in rows:
        cal = r["calibration"]
        for model in ("model2", "model1"):
            s = r.get(model)
            if s is None:
                continue
            ratio = (
                s["error_rms_mm"] / base[model]["error_rms_mm"]
                if s["error_rms_mm"] and base[model].get("error_rms_mm")
                else float("nan")
            )
            print(
                f"{r['zoom']:>5} {model:>6} {r['accepted']:>4} {s['measured']:>4} {s['lost']:>4} "
                f"{s['error_rms_mm'] or float('nan'):8.3f} {s['error_rms_pct'] or float('nan'):7.4f} "
                f"{ratio:5.2f} {s['renders_per_point']:5.1f} "
                f"{s['renders_per_point_without_searched'] or float('nan'):6.1f} "
                f"{s['searched']:>4} {s['search_renders_mean']:4.1f}  {s['failures'] or ''}"
            )
        print(
            f"{'':>5} calib: {cal['fixated']} of {cal['positions']} positions fixated"
            + (f" (not: {cal['not_fixated']})" if cal.get("not_fixated") else "")
            + (f"; FAILED {cal['failed']}" if "failed" in cal else "")
            + f"; refused by the check: {r['refused']}"
            + (
                f"; goal columns {r['goal_columns_px'][0]:.1f}, {r['goal_columns_px'][1]:.1f} px "
                f"(fixed point minus true cx: {r['goal_column_error_px'][0]:+.2f}, "
                f"{r['goal_column_error_px'][1]:+.2f})"
                if "goal_columns_px" in r
                else ""
            )
        )
    total = sum(r["accepted"] for r in rows)
    print(f"{total} accepted targets in all; wall {time.perf_counter() - start:.0f} s")
    if args.json:
        write_json_atomic(args.json, {"field": FIELD, "rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
