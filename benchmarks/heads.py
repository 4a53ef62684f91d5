"""Each shipped head over its whole field, beside calibrated stereo on the same targets, and
accuracy against baseline and focal length for the three kinds of head.

Per shipped head (``headsim.sim.heads.REGISTRY``: the paper's coupled eyes, a motor per
eye, version and vergence) and procedure (Model 2 with the counter-yaw on every head;
one-step fixation where the eyes can be pointed on their own): a realistic head calibrated with tape-measured balls,
then seeded random targets over the field both cameras share at 0.3-1.5 m, kept by
the reach check (what it refused is counted).  The same head's Zhang-calibrated stereo
(``stereo`` procedure) then triangulates the very targets the procedure was given; its
error is given in H from its extrinsics (the midpoint of the optical centres), in H
moved back by the believed entrance pupils, and in camera 1's frame placed by the truth
(the triangulation alone).
Printed: targets accepted and refused, the 3-D error RMS in % of depth over all and by
depth band, and renders per point.

The study (``--study``) runs Model 2 (and fixation) with the baseline and the focal
length scaled about each head's own, and plots the whole field's RMS against each.

    python benchmarks/heads.py [--fast] [--targets 20] [--seed 0] [--seeds 1] [--study] [--plot F]
                               [--json F]

With ``--seeds N`` the table is given over seeds ``--seed`` .. ``--seed + N - 1``: each
cell the median of the seeds' RMS, their range and the targets behind it; the study
runs at ``--seed`` alone.
"""

from __future__ import annotations

import argparse
import copy
import time
from typing import Any

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.files import write_json_atomic
from headsim.runs.progress import Status
from headsim.runs.runner import run_scenario
from headsim.runs.serialise import results_payload
from headsim.scenario.loading import scenario_from_document
from headsim.sim.heads import REGISTRY, shipped
from headsim.sim.model import on_head
from headsim.sim.settings import preset

#: Every shipped head: the kind of eyes it has, and the procedures it runs (fixation
#: where each eye can be pointed on its own).
HEADS = {
    name: (head.mapping.eyes, ("model2", "fixation") if head.mapping.independent else ("model2",))
    for name, head in REGISTRY.items()
}
BANDS = ((0.0, 0.6, "0-0.6 m"), (0.6, 1.0, "0.6-1 m"), (1.0, np.inf, ">= 1 m"))
SCALES = (0.6, 1.0, 1.6)
progress = Status("heads", transient=True)


def field_document(
    head: str, procedure: str, targets: int, balls: int, seed: int, cameras: dict[str, Any]
) -> dict[str, Any]:
    """A realistic head on ``head``, calibrated, then ``targets`` random targets over the
    shared field at 0.3-1.5 m kept by the reach check (as scenarios/realistic_field.toml)."""
    return {
        "description": f"{procedure} over the shared field on the {head} head",
        "seed": seed,
        "head": {"model": head, "preset": "realistic"},
        "cam1": {"noise_std": 1.0, **cameras},
        "cam2": {"noise_std": 1.0, **cameras},
        "experiment": {
            "procedure": procedure,
            "calibration": {
                "targets": balls,
                "depth_m": [0.25, 1.5],
                "position_noise_m": 0.001,
            },
        },
        "scene": {
            "random_targets": {
                "count": targets,
                "depth_m": [0.3, 1.5],
                "lateral": 0.15,
                "vertical": 0.1,
                "within": "reach",
            }
        },
    }


#: Where the board is shown to each head's stereo pair, m from camera 1: the iCub's
#: 320 x 240 cameras find the board's corners only nearer.
BOARD_DISTANCE_M = {"icub": [0.25, 0.5]}


def stereo_document(head: str, seed: int, targets_head: list[list[float]]) -> dict[str, Any]:
    """The same head's Zhang-calibrated stereo (24 board views) on the given targets."""
    return {
        "description": f"calibrated stereo on the {head} head",
        "seed": seed,
        "head": {"model": head, "preset": "realistic"},
        "cam1": {"noise_std": 1.0},
        "cam2": {"noise_std": 1.0},
        "experiment": {
            "procedure": "stereo",
            "stereo": {
                "views": 24,
                "distance_m": BOARD_DISTANCE_M.get(head, [0.4, 1.0]),
                "max_tilt_rad": 0.6,
            },
        },
        "scene": {
            "targets": [
                {"name": f"t{i}", "position_head_m": [float(v) for v in p]}
                for i, p in enumerate(targets_head)
            ]
        },
    }


def run(doc: dict[str, Any], name: str) -> dict[str, Any]:
    return results_payload(run_scenario(scenario_from_document(copy.deepcopy(doc), name)))


def bands(depths: np.ndarray, errors_pct: np.ndarray) -> dict[str, Any]:
    """RMS % of depth over all points and per depth band (NaN errors: failed points)."""
    out: dict[str, Any] = {"count": len(depths), "ok": int(np.isfinite(errors_pct).sum())}
    ok = np.isfinite(errors_pct)
    out["rms_pct"] = float(np.sqrt(np.mean(errors_pct[ok] ** 2))) if ok.any() else None
    for low, high, label in BANDS:
        inside = ok & (depths >= low) & (depths < high)
        out[label] = (
            (float(np.sqrt(np.mean(errors_pct[inside] ** 2))), int(inside.sum()))
            if inside.any()
            else (None, 0)
        )
    return out


def procedure_row(results: dict[str, Any]) -> dict[str, Any]:
    m = results["measurements"]
    depths = np.array([float(x["depth_m"]) for x in m])
    errors = np.array(
        [float(x["error_pct_of_depth"]) if x["status"] == "ok" else np.nan for x in m]
    )
    row = bands(depths, errors)
    summary = next(iter(results["summary"].values()))
    row["renders_per_point"] = summary["renders_per_point"]
    acceptance = results["scenario"]["scene"].get("acceptance", {})
    row["drawn"], row["refused"] = acceptance.get("drawn"), acceptance.get("refused", {})
    row["failures"] = results["failures"]
    return row


def stereo_row(results: dict[str, Any], pupils: bool) -> dict[str, Any]:
    """Stereo's error in H from its extrinsics (the midpoint of the optical centres), or
    with ``pupils`` that H moved back by the believed entrance pupils (what the head knows)."""
    targets = results["experiment"].get("targets", [])
    nodal = results["belief"]["nodal_offset_m"] if pupils else (0.0, 0.0)
    back = np.array([0.0, 0.0, float(np.mean(nodal))])
    depths, errors = [], []
    for t in targets:
        truth = np.asarray(t["truth_head_m"], float)
        depths.append(truth[2])
        if t["status"] == "ok":
            estimate = np.asarray(t["estimate_head_m"], float) + back
            errors.append(100.0 * float(np.linalg.norm(estimate - truth)) / truth[2])
        else:
            errors.append(np.nan)
    row = bands(np.array(depths), np.array(errors))
    row["renders_per_point"] = None
    row["calibration_renders"] = results["experiment"].get("renders")
    # Stereo triangulates in camera 1's frame; H from its extrinsics is the midpoint of the
    # optical centres, which a realistic head's entrance pupils put ahead of the eye axes.
    frames = {f["label"]: f for f in results["experiment"].get("head_frames", [])}
    truth = frames.get("truth", {}) if not pupils else {}
    row["camera_frame_mean_pct"] = truth.get("mean_error_pct_depth")
    row["camera_frame_max_pct"] = truth.get("max_error_pct_depth")
    row["failures"] = results["failures"]
    return row


def fmt_band(value: tuple[float | None, int]) -> str:
    rms, count = value
    return "-" if rms is None else f"{rms:.3f} ({count})"


def table(args: argparse.Namespace) -> list[dict[str, Any]]:
    rows = []
    for head, (kind, procedures) in HEADS.items():
        for procedure in procedures:
            progress(f"{head}: {procedure}")
            start = time.perf_counter()
            results = run(
                field_document(head, procedure, args.targets, args.balls, args.seed, {}),
                f"{head}_{procedure}",
            )
            row = {"head": head, "kind": kind, "procedure": procedure, **procedure_row(results)}
            row["wall_s"] = time.perf_counter() - start
            rows.append(row)
            given = [x["truth_head_m"] for x in results["measurements"]]
            progress(f"{head}: stereo on the same {len(given)} targets")
            stereo = run(stereo_document(head, args.seed, given), f"{head}_stereo")
            rows.append(
                {
                    "head": head,
                    "kind": kind,
                    "procedure": "stereo, H of centres",
                    **stereo_row(stereo, False),
                }
            )
            rows.append(
                {
                    "head": head,
                    "kind": kind,
                    "procedure": "stereo, H of pupils",
                    **stereo_row(stereo, True),
                }
            )
    progress.close()
    return rows


def table_text(rows: list[dict[str, Any]], seed: int) -> str:
    """The table of :func:`table`'s rows."""
    lines = [f"3-D error RMS, % of depth (points); realistic heads after calibration, seed {seed}"]
    header = f"{'head':18} {'procedure':22} {'accepted':>8} {'refused':>8} {'all':>14}"
    header += "".join(f" {label:>14}" for _, _, label in BANDS) + f" {'renders/pt':>10}"
    lines.append(header)
    for r in rows:
        refused = sum(r.get("refused", {}).values()) if isinstance(r.get("refused"), dict) else "-"
        rms = "-" if r["rms_pct"] is None else f"{r['rms_pct']:.3f} ({r['ok']}/{r['count']})"
        rpp = "-" if r["renders_per_point"] is None else f"{r['renders_per_point']:.1f}"
        line = f"{r['head']:18} {r['procedure']:22} {r['count']:>8} {refused!s:>8} {rms:>14}"
        line += "".join(f" {fmt_band(r[label]):>14}" for _, _, label in BANDS) + f" {rpp:>10}"
        lines.append(line)
        if r.get("camera_frame_mean_pct") is not None:
            lines.append(
                f"{'':18} {'  in camera 1 (truth-placed)':22} mean {r['camera_frame_mean_pct']:.3f} "
                f"max {r['camera_frame_max_pct']:.3f} % of depth"
            )
        if r["failures"]:
            lines.append(f"{'':18} failures: {'; '.join(r['failures'])}")
    return "\n".join(lines) + "\n"


def seeds_table(args: argparse.Namespace, seeds: list[int]) -> list[list[dict[str, Any]]]:
    """:func:`table` at each of ``seeds`` (each its own calibration balls, targets and noise)."""
    return [table(argparse.Namespace(**{**vars(args), "seed": seed})) for seed in seeds]


def _median(values: list[float]) -> float:
    return float(np.median(values))


def _spread(values: list[float | None]) -> str:
    """'MEDIAN (MIN-MAX)' of the seeds' values; '-' when none has one."""
    vs = [v for v in values if v is not None]
    if not vs:
        return "-"
    if len(vs) == 1:
        return f"{vs[0]:.3f} (1 seed)"
    return f"{_median(vs):.3f} ({min(vs):.3f}-{max(vs):.3f})"


def seeds_text(per_seed: list[list[dict[str, Any]]], seeds: list[int]) -> str:
    """The table over seeds: each cell the median of the seeds' RMS (min-max), with the
    targets behind it over all seeds."""
    label = f"seeds {seeds[0]}-{seeds[-1]}" if len(seeds) > 1 else f"seed {seeds[0]}"
    lines = [
        f"3-D error RMS, % of depth: median over {label} (min-max over the seeds) [targets "
        "over all seeds]; realistic heads after calibration, each seed its own balls and targets"
    ]
    width = 26
    header = f"{'head':18} {'procedure':22} {'accepted':>8} {'refused':>8} {'all':>{width}}"
    header += "".join(f" {label:>{width}}" for _, _, label in BANDS) + f" {'renders/pt':>10}"
    lines.append(header)
    for index, first in enumerate(per_seed[0]):
        rows = [rs[index] for rs in per_seed]
        refused = (
            sum(sum(r["refused"].values()) for r in rows)
            if all(isinstance(r.get("refused"), dict) for r in rows)
            else "-"
        )
        ok, count = sum(r["ok"] for r in rows), sum(r["count"] for r in rows)
        cells = [f"{_spread([r['rms_pct'] for r in rows])} [{ok}/{count}]"]
        for _, _, band in BANDS:
            cells.append(f"{_spread([r[band][0] for r in rows])} [{sum(r[band][1] for r in rows)}]")
        rpp = [r["renders_per_point"] for r in rows if r["renders_per_point"] is not None]
        shown = f"{_median(rpp):.1f}" if rpp else "-"
        line = f"{first['head']:18} {first['procedure']:22} {count:>8} {refused!s:>8}"
        line += "".join(f" {c:>{width}}" for c in cells) + f" {shown:>10}"
        lines.append(line)
        frame = [r["camera_frame_mean_pct"] for r in rows if r.get("camera_frame_mean_pct")]
        if frame:
            lines.append(
                f"{'':18} {'  in camera 1 (truth-placed)':22} mean {_spread(frame)} % of depth"
            )
        failures = [f for r in rows for f in r["failures"]]
        if failures:
            lines.append(f"{'':18} failures: {'; '.join(failures)}")
    return "\n".join(lines) + "\n"


def study(args: argparse.Namespace) -> list[dict[str, Any]]:
    """Whole-field RMS with the baseline, then the focal length, scaled about each head's."""
    points = []
    for head, (kind, procedures) in HEADS.items():
        settings = on_head(preset("realistic"), shipped(head))
        camera = settings.cameras[0]
        for procedure in procedures:
            for what in ("baseline", "focal"):
                for scale in SCALES:
                    if what == "baseline":
                        doc = field_document(
                            head, procedure, args.targets, args.balls, args.seed, {}
                        )
                        # Built and believed scaled alike: a head built to another design.
                        believed = settings.believed
                        doc["head"]["baseline_m"] = settings.baseline_m * scale
                        doc["belief"] = {"baseline_m": believed.baseline_m * scale}
                        value = believed.baseline_m * scale
                    else:
                        cameras = {"kx": camera.kx * scale, "ky": camera.ky * scale}
                        doc = field_document(
                            head, procedure, args.targets, args.balls, args.seed, cameras
                        )
                        value = camera.kx * scale
                    progress(f"study: {head} {procedure} {what} x{scale}")
                    row = procedure_row(run(doc, f"{head}_{what}_{scale}"))
                    points.append(
                        {
                            "head": head,
                            "kind": kind,
                            "procedure": procedure,
                            "varied": what,
                            "scale": scale,
                            "value": value,
                            "rms_pct": row["rms_pct"],
                            "ok": row["ok"],
                            "count": row["count"],
                        }
                    )
    progress.close()
    return points


def study_text(points: list[dict[str, Any]]) -> str:
    """The study's figures, one row per head, procedure and quantity scaled."""
    lines = ["study: whole-field 3-D error RMS, % of depth (points measured), one quantity scaled"]
    lines.append(
        f"{'head':18} {'procedure':10} {'varied':9} "
        + " ".join(f"{'x' + str(s):>13}" for s in SCALES)
    )
    for head, (_, procedures) in HEADS.items():
        for procedure in procedures:
            for what in ("baseline", "focal"):
                cells = [
                    p
                    for p in points
                    if (p["head"], p["procedure"], p["varied"]) == (head, procedure, what)
                ]
                shown = " ".join(
                    f"{'-' if p['rms_pct'] is None else format(p['rms_pct'], '.3f'):>8} ({p['ok']:>2})"
                    for p in cells
                )
                lines.append(f"{head:18} {procedure:10} {what:9} {shown}")
    return "\n".join(lines) + "\n"


def plot(points: list[dict[str, Any]], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    markers = {"model2": "o-", "fixation": "s--"}
    for ax, what, unit in zip(
        axes, ("baseline", "focal"), ("baseline, mm", "focal length, px"), strict=True
    ):
        for head, (kind, procedures) in HEADS.items():
            for procedure in procedures:
                cells = [
                    p
                    for p in points
                    if (p["head"], p["procedure"], p["varied"]) == (head, procedure, what)
                    and p["rms_pct"] is not None
                ]
                x = [p["value"] * (1000.0 if what == "baseline" else 1.0) for p in cells]
                ax.plot(
                    x,
                    [p["rms_pct"] for p in cells],
                    markers[procedure],
                    label=f"{kind} ({head}), {procedure}",
                )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(unit)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("3-D error RMS, % of depth (whole field)")
    axes[1].legend(fontsize=7)
    fig.suptitle(
        "Accuracy against baseline and focal length, three kinds of head (realistic, calibrated)"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"plot: {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fast", action="store_true", help="few targets and balls: a smoke run")
    parser.add_argument("--targets", type=int, default=None, help="random targets per run (20)")
    parser.add_argument("--balls", type=int, default=None, help="calibration balls (20)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--seeds", type=int, default=1, help="the table over this many seeds from --seed (1)"
    )
    parser.add_argument("--study", action="store_true", help="also the baseline/focal study")
    parser.add_argument("--plot", default=None, help="write the study's plot (PNG) here")
    parser.add_argument("--json", default=None, help="write every figure here")
    args = parser.parse_args()
    args.targets = args.targets or (4 if args.fast else 20)
    args.balls = args.balls or (12 if args.fast else 20)
    figures: dict[str, Any] = {}
    if args.seeds > 1:
        seeds = list(range(args.seed, args.seed + args.seeds))
        figures["tables"] = seeds_table(args, seeds)
        print(seeds_text(figures["tables"], seeds), end="")
    else:
        figures["table"] = table(args)
        print(table_text(figures["table"], args.seed), end="")
    if args.study or args.plot:
        figures["study"] = study(args)
        print("\n" + study_text(figures["study"]), end="")
        if args.plot:
            plot(figures["study"], args.plot)
    if args.json:
        write_json_atomic(args.json, figures)


if __name__ == "__main__":
    main()
