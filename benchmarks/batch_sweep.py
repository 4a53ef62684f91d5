"""The batch back-end against the classic one on one sweep: the quick start's fast variant.

One run, both back-ends on the same conditions (a seeded random sample over the seed,
both cameras' focal lengths and camera 1's radial distortion), each on ``--workers``
local processes, interleaved: ``--rounds`` rounds, each running the next share of the
jobs on the classic back-end and then on the batch back-end (lockstep Model 2; each
job's calibration classic), so that both see the same load.  Wall time (the rounds'
sum), images per second, and every condition's accuracy (the RMS error over its
measured targets, % of depth), per condition and overall.  Targets
not measured count as failures in both.  The quick start's random targets are drawn
``within = "reach"``: a draw that some seed would hide behind another marker is drawn
again (each job's ``results.json`` counts them) rather than refusing the seed.

    python benchmarks/batch_sweep.py [--count 256] [--workers 2] [--worlds 32] [--rounds 4]
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.files import write_json_atomic
from headsim.studies.sweep import SweepOutcome, run_sweep
from headsim.studies.sweep_spec import load_sweep

SWEEP = """description = "Quick start (fast): {count} conditions of seed, focal and distortion"
scenario = "quickstart_reach.toml"
fast = true
{backend}
[random]
count = {count}
seed = 0
[random.fields]
seed = [0, 999999]
"cam1.kx" = [760.0, 910.0]
"cam2.kx" = [760.0, 910.0]
"cam1.k1" = [-0.42, -0.35]
"""


def summary(outcome: SweepOutcome) -> dict[str, Any]:
    """Wall time, images per second and accuracy of one back-end's sweep."""
    records = list(outcome.records.values())
    rms = [r.get("rms_error_pct_depth") for r in records]
    measured = sum(r.get("measurements_ok", 0) for r in records)
    targets = sum(r.get("measurements", 0) for r in records)
    renders = sum(r.get("renders", 0) for r in records)
    weights = [r.get("measurements_ok", 0) for r in records]
    pooled = [
        (value**2, w) for value, w in zip(rms, weights, strict=True) if value is not None and w
    ]
    return {
        "wall_s": outcome.wall_s,
        "conditions": len(records),
        "conditions_failed": len(outcome.failed),
        "targets": targets,
        "targets_measured": measured,
        "renders": renders,
        "targets_redrawn": sum(r.get("targets_redrawn") or 0 for r in records),
        "renders_per_s": renders / outcome.wall_s,
        "rms_error_pct_depth_overall": float(
            np.sqrt(sum(v * w for v, w in pooled) / sum(w for _, w in pooled))
        )
        if pooled
        else None,
        "max_error_mm": max((r.get("max_error_mm") or 0.0) for r in records),
        "per_condition_rms_pct_depth": {
            "median": float(np.nanmedian([np.nan if v is None else v for v in rms])),
            "p95": float(np.nanpercentile([np.nan if v is None else v for v in rms], 95)),
            "max": float(np.nanmax([np.nan if v is None else v for v in rms])),
        },
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=256)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--worlds", type=int, default=32)
    parser.add_argument("--device", default="cpu", choices=("cpu", "cuda"))
    parser.add_argument("--rounds", type=int, default=4, help="interleaved rounds")
    parser.add_argument("--out", default=None, help="directory (default: a temporary one)")
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="batch_sweep_"))
    out.mkdir(parents=True, exist_ok=True)
    outcomes = {}
    from headsim.scenario.loading import resolve_path

    quickstart = resolve_path("quickstart").read_text(encoding="utf-8")
    marker = "vertical = 0.06 # |y_h / z_h|\n"
    if marker not in quickstart:
        raise SystemExit("scenarios/quickstart.toml changed: update this benchmark's edit")
    reach = quickstart.replace(marker, marker + 'within = "reach"\n')
    (out / "quickstart_reach.toml").write_text(reach, encoding="utf-8")
    share = -(-args.count // args.rounds)
    # Each round's share in one chunk per worker: a round's jobs keep every worker busy.
    worlds = max(1, min(args.worlds, -(-share // args.workers)))
    specs = {}
    for name, backend in (
        ("classic", ""),
        ("batch", f'backend = "batch"\n[batch]\nworlds = {worlds}\ndevice = "{args.device}"'),
    ):
        path = out / f"{name}.toml"
        path.write_text(SWEEP.format(count=args.count, backend=backend), encoding="utf-8")
        specs[name] = load_sweep(path)
    walls = {name: 0.0 for name in specs}
    drawn: dict[str, float] = {}  # what lockstep drew, over the rounds
    for r in range(args.rounds):
        for name, spec in specs.items():
            # This round's share of the jobs (not stop_after: a pool finishes the chunks
            # it already took, work that a later round would redo).
            part = dataclasses.replace(spec, jobs=spec.jobs[r * share : (r + 1) * share])
            outcomes[name] = run_sweep(part, out / name, workers=args.workers, progress=False)
            walls[name] += outcomes[name].wall_s
            for key, value in (outcomes[name].rendered or {}).items():
                drawn[key] = (
                    max(drawn.get(key, 0), value)
                    if key == "largest"
                    else (drawn.get(key, 0) + value)
                )
    for name, spec in specs.items():  # the aggregate (every job is done: nothing runs)
        outcomes[name] = run_sweep(spec, out / name, workers=args.workers, progress=False)
        outcomes[name].wall_s = walls[name]
    figures: dict[str, Any] = {name: summary(o) for name, o in outcomes.items()}
    rendered = drawn
    figures["batch"]["lockstep"] = rendered
    figures["batch"]["jobs_on_the_classic_path"] = sum(
        r.get("backend") == "classic" for r in outcomes["batch"].records.values()
    )
    classic, batch = (outcomes[n].records for n in ("classic", "batch"))
    pairs = [
        (classic[k].get("rms_error_pct_depth"), batch[k].get("rms_error_pct_depth"))
        for k in classic
    ]
    both = [(c, b) for c, b in pairs if c is not None and b is not None]
    diff = np.array([b - c for c, b in both])
    figures["per_condition_batch_minus_classic_pct_depth"] = {
        "n": int(diff.size),
        "median": float(np.median(diff)),
        "p95_abs": float(np.percentile(np.abs(diff), 95)),
        "max_abs": float(np.abs(diff).max()),
    }
    figures["wall_ratio_batch_over_classic"] = outcomes["batch"].wall_s / outcomes["classic"].wall_s
    write_json_atomic(out / "figures.json", figures)
    plot(both, out / "batch_vs_classic.png", args.count)
    for name in ("classic", "batch"):
        f = figures[name]
        print(
            f"{name:8s} {f['wall_s']:7.1f} s  {f['renders_per_s']:7.1f} renders/s  "
            f"{f['targets_measured']}/{f['targets']} targets measured, "
            f"{f['conditions_failed']} conditions failed, RMS "
            f"{f['rms_error_pct_depth_overall']:.3f} % of depth, max {f['max_error_mm']:.2f} mm"
        )
    print(
        f"per condition, batch - classic: {figures['per_condition_batch_minus_classic_pct_depth']}"
    )
    print(f"lockstep: {rendered}")
    print(f"figures: {out / 'figures.json'}, {out / 'batch_vs_classic.png'}")


def plot(both: list[tuple[float, float]], path: Path, count: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c, b = np.array(both).T
    fig, ax = plt.subplots(figsize=(5, 5))
    ax.scatter(c, b, s=8, alpha=0.6)
    top = float(max(c.max(), b.max())) * 1.05
    ax.plot([0, top], [0, top], "k--", lw=0.8)
    ax.set_xlabel("classic renderer: RMS error, % of depth")
    ax.set_ylabel("batch (lockstep Model 2): RMS error, % of depth")
    ax.set_title(f"Quick start (fast), {len(both)} of {count} conditions")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
