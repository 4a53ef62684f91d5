"""Lockstep Model 2 against the classic path on the quick start's targets (fast and full).

Per variant: the classic calibration (Sec. V) gives what the head knows; the classic
Model 2 (the quick start's own: one servo, its gains and eye pose carried from target to
target) and lockstep Model 2 (one head a target, all at once, :mod:`headsim.lockstep.servo`)
measure every target with it.  Per target: both estimates' errors and their difference,
in % of depth.  The yardstick: the classic path against itself at another seed of the
head's image noise and count draws (``settings.seed`` + 1), the servo's own noise.

    python benchmarks/lockstep_model2.py [--out DIR] [--seeds 0 1 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.files import write_json_atomic
from headsim.lockstep.model2_run import run_model2_lockstep
from headsim.procedures.model2 import run_model2
from headsim.runs.calibrate import calibrate
from headsim.runs.events import Hub
from headsim.scenario.loading import load_scenario


def compare(fast: bool, seed: int) -> list[dict[str, Any]]:
    """Each target of the quick start (``fast`` variant, scenario ``seed``): both paths."""
    scenario = load_scenario("quickstart", fast=fast, seed=seed)
    run, _ = calibrate(scenario, Hub(()))
    if run is None:
        raise SystemExit(f"the classic calibration failed (seed {seed})")
    knowledge = run.knowledge
    start = time.perf_counter()
    classic, _ = run_model2(scenario, Hub(()), knowledge, "calibrated")
    classic_s = time.perf_counter() - start
    other = dataclasses.replace(
        scenario, settings=dataclasses.replace(scenario.settings, seed=scenario.settings.seed + 1)
    )
    again, _ = run_model2(other, Hub(()), knowledge, "calibrated")
    start = time.perf_counter()
    lockstep = run_model2_lockstep(scenario, knowledge)
    lockstep_s = time.perf_counter() - start
    rows = []
    for c, a, lk in zip(classic, again, lockstep, strict=True):
        m, depth = c.measurement, c.measurement.depth_m

        def pct(estimate: np.ndarray, depth: float = depth, m: Any = m) -> float:
            return float(100 * np.linalg.norm(estimate - m.estimate_head_m) / depth)

        rows.append(
            {
                "variant": "fast" if fast else "full",
                "seed": seed,
                "target": m.name,
                "first": c is classic[0],
                "depth_m": depth,
                "classic_ok": m.ok,
                "lockstep_status": lk.status,
                "classic_error_pct": m.error_pct_of_depth if m.ok else None,
                "lockstep_error_pct": lk.error_pct_of_depth if lk.ok else None,
                "lockstep_vs_classic_pct": pct(lk.estimate_head_m) if m.ok and lk.ok else None,
                "classic_reseeded_vs_classic_pct": (
                    pct(a.measurement.estimate_head_m) if m.ok and a.measurement.ok else None
                ),
                "classic_renders": m.renders,
                "lockstep_renders": lk.renders,
                "classic_s": classic_s,
                "lockstep_s": lockstep_s,
            }
        )
    return rows


def spread(values: list[float]) -> dict[str, float]:
    a = np.abs(np.array(values))
    return {
        "n": int(a.size),
        "median": float(np.median(a)),
        "p90": float(np.percentile(a, 90)),
        "max": float(a.max()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None, help="directory (default: a temporary one)")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="lockstep_model2_"))
    out.mkdir(parents=True, exist_ok=True)
    rows = [row for seed in args.seeds for fast in (True, False) for row in compare(fast, seed)]
    for r in rows:
        lk = r["lockstep_vs_classic_pct"]
        rs = r["classic_reseeded_vs_classic_pct"]
        print(
            f"{r['variant']:4s} seed {r['seed']:3d} {r['target']:9s} {r['depth_m']:.3f} m  "
            f"classic {r['classic_error_pct'] or float('nan'):.3f} %  lockstep "
            f"{r['lockstep_error_pct'] or float('nan'):.3f} % ({r['lockstep_status']})  "
            f"lockstep-classic {lk if lk is not None else float('nan'):.3f} %  "
            f"reseeded-classic {rs if rs is not None else float('nan'):.3f} %"
        )
    figures = {
        "rows": rows,
        "targets": len(rows),
        "lockstep_ok": sum(r["lockstep_status"] == "ok" for r in rows),
        "classic_ok": sum(bool(r["classic_ok"]) for r in rows),
        "lockstep_vs_classic_pct": spread(
            [r["lockstep_vs_classic_pct"] for r in rows if r["lockstep_vs_classic_pct"] is not None]
        ),
        # The first target: both paths start alike (home, no gain learnt).
        "lockstep_vs_classic_first_target_pct": spread(
            [
                r["lockstep_vs_classic_pct"]
                for r in rows
                if r["first"] and r["lockstep_vs_classic_pct"] is not None
            ]
        ),
        "classic_reseeded_vs_classic_pct": spread(
            [
                r["classic_reseeded_vs_classic_pct"]
                for r in rows
                if r["classic_reseeded_vs_classic_pct"] is not None
            ]
        ),
    }
    write_json_atomic(out / "figures.json", figures)
    print(
        f"targets {figures['targets']}: lockstep ok {figures['lockstep_ok']}, classic ok "
        f"{figures['classic_ok']}"
    )
    print(f"|lockstep - classic|, % of depth: {figures['lockstep_vs_classic_pct']}")
    print(f"  first targets (same start): {figures['lockstep_vs_classic_first_target_pct']}")
    print(f"|classic reseeded - classic|, % of depth: {figures['classic_reseeded_vs_classic_pct']}")
    print(f"figures: {out / 'figures.json'}")


if __name__ == "__main__":
    main()
