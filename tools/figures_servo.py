"""The documentation's figures of rendering and the servo: fidelity floors, windows, reach and zoom, areas."""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from figures_common import benchmark, effort, payload, span, table

# --- rendering fidelity -------------------------------------------------------------

#: Marker poses and chessboard poses per setting (``render_fidelity.py``: 200 and 20).
POSES, BOARDS = 50, 5


@functools.cache
def _floors(offsamples: int, supersample: int, head: str = "ideal") -> tuple[str, str]:
    """'p50 / p95' of the marker-centroid and the chessboard-corner error, px."""
    from headsim.sim.settings import RenderFidelity

    rf = benchmark("render_fidelity")
    fidelity = RenderFidelity(offsamples, supersample)
    marker, _ = rf.marker_floor(fidelity, POSES, 0, head)
    corner = rf.corner_floor(fidelity, BOARDS, 1, head)
    return (
        f"{np.nanmedian(marker):.3f} / {np.nanpercentile(marker, 95):.3f}",
        f"{np.median(corner):.3f} / {np.percentile(corner, 95):.3f}",
    )


def render_fidelity() -> str:
    """The floors against multisampling and supersampling, ideal camera, and the default's."""
    from headsim.sim.settings import RenderFidelity

    rf = benchmark("render_fidelity")
    default = RenderFidelity()
    rows = []
    for f in rf.SETTINGS:
        label = f"{f.supersample} (the default)" if f == default else str(f.supersample)
        rows.append((str(f.offsamples), label, *_floors(f.offsamples, f.supersample)))
    marker, corner = _floors(default.offsamples, default.supersample)
    coarse_marker, coarse_corner = _floors(4, 1)
    return (
        f"{POSES} marker poses and {BOARDS} chessboard poses ({BOARDS * 48} corners) per "
        "setting, seeds 0 and 1:\n\n"
        + table(("offsamples", "supersample", "marker p50 / p95 px", "corner p50 / p95 px"), rows)
        + f"\nEvery preset (ideal, paper, realistic) renders at ({default.offsamples}, "
        f"{default.supersample}) by default: a marker floor of {marker.split(' / ')[1]} px and a "
        f"chessboard-corner floor of {corner.split(' / ')[1]} px (95th percentiles, against "
        f"{coarse_marker.split(' / ')[1]} and {coarse_corner.split(' / ')[1]} px at (4, 1)).\n"
    )


def render_fidelity_presets() -> str:
    """The default's floors with each preset's own cameras (lens and image noise included)."""
    from headsim.sim.settings import RenderFidelity

    default = RenderFidelity()
    rows = [
        (head, *_floors(default.offsamples, default.supersample, head))
        for head in ("ideal", "paper", "realistic")
    ]
    return table(("preset", "marker p50 / p95 px", "corner p50 / p95 px"), rows)


#: Poses per preset of the batch renderer's centroid figures (``batch_render.py``: 16).
BATCH_POSES = 16


def batch_centroids() -> str:
    """The batch renderer's marker centroid against the classic render's and the pinhole's,
    per sub-pixel samples per axis, beside the classic renderer's own floor."""
    from headsim.sim.settings import preset

    def cell(s: dict[str, float]) -> str:
        return f"{s['median']:.3f} / {s['p95']:.3f} / {s['max']:.3f}"

    br = benchmark("batch_render")
    rows = []
    for name in ("ideal", "paper"):
        figures = br.agreement(preset(name), BATCH_POSES, 0, (1, 2, 4))
        rows.append((name, "classic (default)", "-", cell(figures["classic_to_truth_px"])))
        for samples in (1, 2, 4):
            f = figures[f"spp{samples}"]
            rows.append(
                (
                    name,
                    f"batch, {samples} x {samples}",
                    cell(f["to_classic_px"]),
                    cell(f["to_truth_px"]),
                )
            )
    return (
        f"{BATCH_POSES} seeded eye and neck poses x 2 eyes per preset, the red marker's centroid "
        "(px, median / p95 / max):\n\n"
        + table(
            ("cameras", "renderer, samples per pixel", "to the classic render", "to the pinhole"),
            rows,
        )
    )


# --- relative positioning over all twelve areas -------------------------------------

#: Objects per area (``relative_areas.py``: 20), and per area in the other seed and preset.
PER_AREA, PER_AREA_VARIANTS = 8, 4


def _area_run(
    per_area: int, preset: str = "paper", seed: int = 0, near_axis: int = 10
) -> tuple[str, list[dict[str, Any]]]:
    """One ``relative_areas.area_study``: its objects and each test's agreement, in words."""
    ra = benchmark("relative_areas")
    study = ra.area_study(per_area, preset, seed, near_axis, progress=False)
    rows = study["rows"]
    seen = [r for r in rows if r["seen"] and not r["near_axis"]]
    per_area_counts = [sum(r["true"] == a for r in seen) for a in range(1, 13)]
    parts = []
    for test, label, margin in (
        ("gain", "the gain-normalised test", "gain_margin_px"),
        ("paper", "the paper's", "margin_px"),
    ):
        misses = [r for r in seen if r[test] != r["true"]]
        outside = [r for r in seen if r[margin] > 2.0]
        outside_ok = sum(r[test] == r["true"] for r in outside)
        where = ", ".join(
            f"S{r['true']} called S{r[test]} {'outside' if r[margin] > 2.0 else 'inside'} the margin"
            for r in misses
        )
        parts.append(
            f"{label} {len(seen) - len(misses)} of {len(seen)}"
            + (f" ({where})" if where else "")
            + f", {outside_ok} of {len(outside)} outside the 2 px margin"
        )
    return (
        f"{len(rows)} objects in {study['spread_layouts']} layouts"
        + (f" plus {study['near_layouts']} near Z_h" if study["near_layouts"] else "")
        + f", {span(per_area_counts, 0, ' to ')} seen in each area S1-S12; they agree with the "
        f"geometry with {'; with '.join(parts)}"
    ), rows


def relative_areas() -> str:
    """The twelve areas on the paper's cameras (seed 0), another seed and the realistic head."""
    ra = benchmark("relative_areas")
    main, rows = _area_run(PER_AREA)
    seed_1, _ = _area_run(PER_AREA_VARIANTS, seed=1, near_axis=0)
    realistic, _ = _area_run(PER_AREA_VARIANTS, "realistic", near_axis=0)
    _, near = ra.tally(rows)
    z = near["near Z_h (|x/z| <= 0.02)"]
    return (
        f"`relative_areas.py --per-area {PER_AREA}` (paper's cameras, seed 0; layouts are added "
        f"until every area holds {PER_AREA} objects seen in all four images): {main}. Within "
        f"|x/z| <= 0.02 of Z_h ({z['objects']} objects in the magnitude areas) the paper's test "
        f"misclassifies {z['paper']['misclassified']}, the gain-normalised "
        f"{z['gain']['misclassified']}. With `--per-area {PER_AREA_VARIANTS} --near-axis 0`, "
        f"seed 1: {seed_1}; `--preset realistic`: {realistic} (its geometric truth puts the "
        "lines through the yaw axes, not the 20 mm nodal offset).\n"
    )


# --- windows and averaged fixation on the bench's ideal-camera points ---------------


class _Detections:
    """Where the servo found its target in each image it looked at (None: not found), px."""

    def __init__(self) -> None:
        self.seen: list[tuple[float, float] | None] = []

    def notify(self, event: object, at: Any) -> None:
        from headsim.active.events import Detected

        if isinstance(event, Detected):
            self.seen.append(event.uv_px)


@functools.cache
def _bench_points(windows: bool = True, average: bool = False) -> dict[str, Any]:
    """Model 2 on ``headsim bench``'s 12 ideal-camera targets (seed 0) with this servo config,
    run as a scenario: the measurements, every detection the servo made, renders and full
    frames per point."""
    from headsim.runs.runner import run_scenario
    from headsim.scenario.loading import scenario_from_document
    from headsim.studies import experiments
    from headsim.studies.targets import random_targets_head

    rng = np.random.default_rng(0)
    points = np.concatenate(
        [
            random_targets_head(rng, 4, band, vertical=(-0.15, 0.15))
            for band in experiments.DEPTH_BANDS_M
        ]
    )
    doc = {
        "description": "Model 2 on the bench's ideal-camera targets",
        "seed": 0,
        "head": {"preset": "ideal"},
        "experiment": {
            "procedure": "model2",
            "servo": {"windows": windows, "average_fixation": average},
        },
        "scene": {
            "targets": [
                {"name": f"point_{k}", "position_head_m": [float(v) for v in p]}
                for k, p in enumerate(points)
            ]
        },
    }
    detections = _Detections()
    result = run_scenario(scenario_from_document(doc, "bench_points"), [detections])
    measured = [r.measurement for r in result.records]
    return {
        "measured": measured,
        "seen": detections.seen,
        # The first point probes the servo's gain: the bench leaves it out of renders per point.
        "renders_per_point": float(np.mean([m.renders for m in measured[1:]])),
        "frames_per_point": result.rendered_frames["experiment"] / len(points),
        "rms_pct": float(np.sqrt(np.mean([m.error_pct_of_depth**2 for m in measured if m.ok]))),
    }


def windows() -> str:
    """Windows on against full frames only: the answers, the pixels, the renders."""
    on, off = _bench_points(), _bench_points(windows=False)
    estimate = max(
        float(np.max(np.abs(a.estimate_head_m - b.estimate_head_m)))
        for a, b in zip(on["measured"], off["measured"], strict=True)
    )
    same = len(on["seen"]) == len(off["seen"]) and all(
        (a is None) == (b is None) for a, b in zip(on["seen"], off["seen"], strict=True)
    )
    detection = (
        f"detections within {max(float(np.max(np.abs(np.subtract(a, b)))) for a, b in zip(on['seen'], off['seen'], strict=True) if a is not None and b is not None):.0e} px"
        if same
        else "the servo's detections in another sequence"
    )
    return (
        f"  Windows change no answer (the bench's {len(on['measured'])} ideal-camera targets, "
        f"seed 0, at the (4, 2) default: estimates within {estimate:.0e} m, {detection} of full "
        f"frames) and cut the pixels per Model 2 point from {off['frames_per_point']:.1f} to "
        f"{on['frames_per_point']:.2f} full frames (renders per point "
        f"{on['renders_per_point']:.1f}, the previews counted, against "
        f"{off['renders_per_point']:.1f} with full frames only).\n"
    )


def averaged_fixation() -> str:
    """The renders that averaging each fixation over one pixel costs on the bench's points."""
    one, averaged = _bench_points(), _bench_points(average=True)
    return (
        "  Covering the period cancels it at every zoom alike, for about twice the renders per "
        f"point (the bench's "
        f"{len(one['measured'])} ideal-camera targets: {one['renders_per_point']:.1f} -> "
        f"{averaged['renders_per_point']:.1f} renders; 3-D error RMS "
        f"{one['rms_pct']:.3f} -> {averaged['rms_pct']:.3f} % of depth).\n"
    )


def chessboard_windows() -> str:
    """What ``headsim run chessboard`` drew: windows, previews, misses."""
    e = effort(payload("chessboard"))
    return (
        f"  `headsim run chessboard` (seed 0, its calibration included): {e['windows']} windows "
        f"and {e['previews']} previews among {e['renders']} renders ({e['images']} full frames, "
        f"{e['retakes']} windows retaken whole); {e['frames']:.1f} full frames of pixels.\n"
    )


# --- every target the reach check accepts, across zoom ------------------------------

#: ``reach_and_zoom.py``'s run, smaller: random targets and calibration positions (200, 60).
ZOOM_TARGETS, ZOOM_CALIBRATION = 30, 12
ZOOMS = (0.7, 1.0, 1.3, 1.6, 2.0)
#: The four configurations: goal columns, averaged fixation; and their rows' labels.
CONFIGS = (
    ("fixed-point", True, "zoom fixed point, averaged"),
    ("fixed-point", False, "zoom fixed point, one image"),
    ("centre", True, "image centre, averaged"),
    ("centre", False, "image centre, one image (the defaults)"),
)
MODELS = (("model2", "Model 2"), ("model1", "Model 1"))


def _zoom_points() -> np.ndarray:
    rz = benchmark("reach_and_zoom")
    return rz.draw_targets(np.random.default_rng(0), ZOOM_TARGETS)


@functools.cache
def _zoom_run(zoom: float, goal: str, average: bool) -> dict[str, Any]:
    rz = benchmark("reach_and_zoom")
    return rz.run_zoom(zoom, _zoom_points(), ZOOM_CALIBRATION, 0, goal, average_fixation=average)


def _ratios(rows: list[dict[str, Any]], model: str) -> dict[float, dict[str, float]]:
    rz = benchmark("reach_and_zoom")
    return rz.paired_ratios(rows, model, np.random.default_rng([0, 11]))


def _config_rows(goal: str, average: bool) -> list[dict[str, Any]]:
    return [_zoom_run(z, goal, average) for z in ZOOMS]


def reach_zoom() -> str:
    """Accepted, measured and renders per zoom and configuration; the RMS ratio to 1x."""
    runs = [r for goal, avg, _ in CONFIGS for r in _config_rows(goal, avg)]
    accepted = [r["accepted"] for r in _config_rows("centre", False)]
    stats = [r[m] for r in runs for m, _ in MODELS]
    fixated = [r["calibration"]["fixated"] for r in runs]
    searched = [r["model2"] for r in runs if r["model2"]["searched"]]
    searched1 = [r["model1"] for r in runs if r["model1"]["searched"]]
    causes: dict[str, int] = {}
    for s in stats:
        for cause, n in s["failure_causes"].items():
            causes[cause] = causes.get(cause, 0) + n
    failed = ", ".join(f"{n} {c}" for c, n in sorted(causes.items())) or "none failed"
    one_image = [r for goal, avg, _ in CONFIGS if not avg for r in _config_rows(goal, avg)]
    fixed_avg = _config_rows("fixed-point", True)

    def per_point(rs: list[dict[str, Any]], model: str, key: str = "renders_per_point") -> str:
        return span((r[model][key] for r in rs if r[model][key] is not None), 1)

    rows, common = [], 0
    for goal, avg, label in CONFIGS:
        config = _config_rows(goal, avg)
        for model, name in MODELS:
            ratios = _ratios(config, model)
            common = int(ratios[1.0]["targets"])
            cells = []
            for zoom in (0.7, 1.3, 1.6, 2.0):
                q = ratios[zoom]
                cells.append(
                    f"{q['ratio']:.2f} ({q['ratio_low']:.2f}-{q['ratio_high']:.2f})"
                    if zoom == 0.7
                    else f"{q['ratio']:.2f}"
                )
            one_x = next(r for r in config if r["zoom"] == 1.0)[model]
            rows.append((f"{label}, {name}", *cells, f"{one_x['error_rms_mm']:.3f} mm"))
    return (
        f"`benchmarks/reach_and_zoom.py --targets {ZOOM_TARGETS} --calibration "
        f"{ZOOM_CALIBRATION}` (seed 0; one set of points over 0.4-1.4 m, |x/z| <= 0.3, "
        "|y/z| <= 0.15, the same at 0.7x, 1x, 1.3x, 1.6x and 2x the paper's focal length; the "
        f"reach check accepts {', '.join(map(str, accepted[:-1]))} and {accepted[-1]} of them, "
        f"{sum(accepted)} in all; each measured with Model 2 and with Model 1), in four "
        "configurations (goal columns at the zoom's fixed point, `--goal fixed-point`, or the "
        "image centre; one image per fixation, the default, or `--average-fixation`): "
        f"{sum(s['measured'] for s in stats)} of {sum(s['targets'] for s in stats)} measured "
        f"(failures by cause: {failed}); the calibration ({ZOOM_CALIBRATION} positions, "
        f"eyes allowed to turn in) fixated {span(fixated, 0)} of {ZOOM_CALIBRATION} at every "
        f"zoom. Model 2 searched for {span((s['searched'] for s in searched), 0)} targets per "
        f"zoom at {span((s['search_renders_mean'] for s in searched), 1)} extra renders each "
        "(one full frame per pose, or a binned preview per pose of a scan); Model 1 for "
        f"{span((s['searched'] for s in searched1), 0) if searched1 else '0'} (a scan of the "
        "neck's ranges for a new target the start pose does not show). "
        f"Renders per point, one image: {per_point(one_image, 'model2')} (Model 2, "
        f"{per_point(one_image, 'model2', 'renders_per_point_without_searched')} without the "
        f"searched targets) and {per_point(one_image, 'model1')} (Model 1); averaged, fixed "
        f"point: {per_point(fixed_avg, 'model2')} (Model 2, "
        f"{per_point(fixed_avg, 'model2', 'renders_per_point_without_searched')} without) and "
        f"{per_point(fixed_avg, 'model1')} (Model 1), most at 0.7x. 3-D error RMS as a ratio to "
        f"1x on the {common} points every zoom measured (95 % bootstrap interval):\n\n"
        + table(
            ("goal columns, fixation, model", "0.7x", "1.3x", "1.6x", "2x", "1x, all measured"),
            rows,
        )
    )


def reach_zoom_angles() -> str:
    """The fixation angles' and the calibration's errors behind the rows, and 0.5x."""

    def fixation_std(goal: str, avg: bool, zoom: float | None = None) -> list[float]:
        rs = [r for r in _config_rows(goal, avg) if zoom is None or r["zoom"] == zoom]
        return [s for r in rs for s in r["fixation_error_mrad"]["std"]]

    directions = [
        1e3 * abs(e)
        for goal, avg, _ in CONFIGS
        for r in _config_rows(goal, avg)
        for e in r["calibration"]["alpha_e_error_rad"]
    ]
    at_1x = {
        goal: [
            next(r for r in _config_rows(goal, avg) if r["zoom"] == 1.0)["model2"]["error_rms_mm"]
            for g, avg, _ in CONFIGS
            if g == goal
        ]
        for goal in ("centre", "fixed-point")
    }
    half = _zoom_run(0.5, "fixed-point", True)
    pair = [half, next(r for r in _config_rows("fixed-point", True) if r["zoom"] == 1.0)]
    q = {m: _ratios(pair, m)[0.5] for m, _ in MODELS}
    return (
        "In these runs Model 2's fixation angles are off by (std, Ca1/Ca2) "
        f"{' / '.join(f'{s:.3f}' for s in fixation_std('fixed-point', False, 0.7))} mrad at 0.7x "
        f"with one image, {span(fixation_std('fixed-point', True), 3)} averaged at every zoom; "
        f"the calibrated initial directions are {span(directions, 2)} mrad off; Model 2's error "
        f"at 1x is {span(at_1x['centre'], 2)} mm with image-centre columns against "
        f"{span(at_1x['fixed-point'], 2)} mm at the fixed point. At 0.5x (fixed point, averaged): "
        f"{half['model2']['measured']} and {half['model1']['measured']} of {half['accepted']} "
        f"accepted measured by Model 2 and Model 1, {half['model2']['lost'] + half['model1']['lost']} "
        f"lost, calibration {half['calibration']['fixated']} of {ZOOM_CALIBRATION}; ratio "
        + " and ".join(
            f"{q[m]['ratio']:.2f} ({q[m]['ratio_low']:.2f}-{q[m]['ratio_high']:.2f}) for {name}"
            for m, name in MODELS
        )
        + f", on the {q['model2']['targets']} points both zooms measured.\n"
    )


# --- the shipped heads beside their stereo, and the baseline/focal study -------------


def heads() -> str:
    """benchmarks/heads.py's table over seeds 0-4 and its study (20 targets, 20 balls,
    the study at seed 0)."""
    import argparse

    from figures_common import SEEDS

    bench = benchmark("heads")
    args = argparse.Namespace(targets=20, balls=20, seed=SEEDS[0])
    per_seed = bench.seeds_table(args, list(SEEDS))
    points = bench.study(args)
    return (
        f"`python benchmarks/heads.py --targets 20 --balls 20 --seeds {len(SEEDS)} --study "
        "--plot docs/heads-study.png` (the study at seed 0 alone):\n\n"
        "```\n"
        + bench.seeds_text(per_seed, list(SEEDS))
        + "\n"
        + bench.study_text(points)
        + "```\n"
    )
