"""Seeded accuracy experiments over the procedures: the figures behind the benchmarks.

Each function builds its own simulators, runs a procedure on seeded random
targets and returns plain figures (dicts of floats and lists) ready for JSON.
Errors are estimate minus truth in the head frame H; "% of depth" divides by
the true z_h.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Sequence
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np

from headsim.active.calibration_file import knowledge_from_block
from headsim.active.measurement import HeadKnowledge, Measurement, body_target
from headsim.estimators.areas import AreaComparison, tally_areas
from headsim.runs.progress import Progress, quiet
from headsim.runs.result import RunResult
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import scenario_from_document
from headsim.scenario.reach import ReachHead
from headsim.scenario.reach_check import target_refusals
from headsim.scenario.scene import start_head_to_world
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.studies.render_clock import RenderClock
from headsim.studies.scenario_runs import knowledge_file, preset_of, scenario_with_head
from headsim.studies.targets import random_targets_head, visible_vertical_range
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))
BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))
DEPTH_BANDS_M = ((0.3, 0.6), (0.6, 1.0), (1.0, 1.5))
#: Rows within this many px of the image centre row count as "near the centre row".
CENTRE_ROW_BAND_PX = 100.0


def centre_row_offset_px(settings: HeadSettings, m: Measurement) -> float:
    """Largest |v - centre row| of the target over both cameras' y images, px."""
    return max(
        abs(m.details["v11_px"] - settings.cameras[0].image_centre[1]),
        abs(m.details["v21_px"] - settings.cameras[1].image_centre[1]),
    )


def error_figures(measurements: Sequence[Measurement]) -> dict[str, Any]:
    """RMS errors of successful measurements: 3-D and per axis, mm and % of depth."""
    ok = [m for m in measurements if m.ok]
    if not ok:
        return {"count": 0, "failed": len(measurements)}
    err = np.array([m.error_head_m for m in ok])
    depth = np.array([m.depth_m for m in ok])
    pct = 100 * err / depth[:, None]
    return {
        "count": len(ok),
        "failed": len(measurements) - len(ok),
        "rms_3d_mm": float(1000 * np.sqrt(np.mean(np.sum(err**2, axis=1)))),
        "rms_3d_pct_depth": float(np.sqrt(np.mean(np.sum(pct**2, axis=1)))),
        "rms_pct_depth_xyz": [float(v) for v in np.sqrt(np.mean(pct**2, axis=0))],
        "max_3d_pct_depth": float(np.max(np.linalg.norm(pct, axis=1))),
    }


def reachable(settings: HeadSettings, targets_head: Sequence[np.ndarray]) -> list[bool]:
    """Whether a model2 scenario accepts each red-marker target (H, m) in turn: in reach,
    seen by both cameras, hidden by nothing (:func:`headsim.scenario.reach_check.target_refusals`)."""
    world = start_head_to_world(settings, np.asarray(targets_head, dtype=float).reshape(-1, 3))
    listed = [("marker_red", p) for p in world]
    refusals = target_refusals(ReachHead.of(settings), "model2", "default", listed)
    return [r is None for r in refusals]


def _model2_points(
    settings: HeadSettings,
    targets_head: Sequence[np.ndarray],
    calibration: dict[str, Any] | None = None,
) -> RunResult:
    """Model 2 on each of ``targets_head`` (H, m) by the head ``settings``, after the
    ``[experiment.calibration]`` table ``calibration`` (None: none)."""
    experiment: dict[str, Any] = {"procedure": "model2"}
    if calibration is not None:
        experiment["calibration"] = calibration
    doc = {
        "description": "Model 2 on a study's targets",
        "experiment": experiment,
        "scene": {
            "targets": [
                {"name": f"point_{k}", "position_head_m": [float(v) for v in p]}
                for k, p in enumerate(targets_head)
            ]
        },
    }
    return run_scenario(scenario_with_head(doc, "model2_points", settings))


def model2_accuracy(
    settings: HeadSettings,
    rng: np.random.Generator,
    *,
    targets_per_band: int = 20,
    calibrate: bool = False,
    calibration_targets: int = 60,
    vertical: tuple[float, float] | None = None,
    progress: Progress = quiet,
) -> dict[str, Any]:
    """Model 2 over the depth bands, after Sec. V calibration if ``calibrate``.

    Each is a scenario: the calibration's balls are the scenario's own (drawn
    from its seed), the targets drawn from ``rng``, those a scenario refuses
    (out of reach, hidden) left out and counted (``refused_targets``).
    Returns errors per band and overall, split by rows near the centre row,
    renders per point, servo residuals, wall time per point (the run's
    measurement phase, its simulator's set-up included) and per render, the
    calibration's recovered offsets beside the truth, and y errors under three
    conditions: image-centre rows (Table VI), principal rows given (Table V)
    and the extended calibration.
    """
    out: dict[str, Any] = {}
    vertical = vertical or visible_vertical_range(settings)
    keys, drawn = [], []
    for low, high in DEPTH_BANDS_M:
        for p_head in random_targets_head(rng, targets_per_band, (low, high), vertical=vertical):
            keys.append(f"{low:.1f}-{high:.1f} m")
            drawn.append(p_head)
    accepted = reachable(settings, drawn)
    keys = [k for k, ok in zip(keys, accepted, strict=True) if ok]
    targets_head = [p for p, ok in zip(drawn, accepted, strict=True) if ok]
    out["refused_targets"] = len(drawn) - len(targets_head)
    progress("calibrating the initial directions" if calibrate else "model 2")
    calibration = {"targets": calibration_targets} if calibrate else None
    result = _model2_points(settings, targets_head, calibration)
    measurements = [r.measurement for r in result.records]
    report = result.calibration
    knowledge = HeadKnowledge()
    if report is not None and report.knowledge is not None:
        knowledge = knowledge_from_block({"knowledge": asdict(report.knowledge)})
        vertical_reference = report.vertical_reference
        out["calibration"] = {
            "alpha_e_rad": report.alpha_e_rad,
            "truth_alpha_e_rad": report.alpha_e_truth_rad,
            "error_rad": report.alpha_e_error_rad,
            "std_error_rad": report.alpha_e_std_rad,
            "samples": report.fixated,
            "renders": report.renders.total,
            "v0_px": None if vertical_reference is None else vertical_reference.v0_px,
            "kx_over_ky": None if vertical_reference is None else vertical_reference.kx_over_ky,
        }
    bands: dict[str, list[Measurement]] = {f"{lo:.1f}-{hi:.1f} m": [] for lo, hi in DEPTH_BANDS_M}
    for key, m in zip(keys, measurements, strict=True):
        bands[key].append(m)
    clock = RenderClock(settings)
    try:
        tenth_render = clock.sample(10)
    finally:
        clock.close()
    wall = result.timing_s.get("experiment", math.nan)
    extra: dict[str, list[Measurement]] = {}
    if calibrate:  # the same targets with less knowledge, for the y budget
        plain = HeadKnowledge(alpha_e=knowledge.alpha_e)
        principal = replace(plain, v0=tuple(c.principal[1] for c in settings.cameras))  # type: ignore[arg-type]
        with tempfile.TemporaryDirectory() as folder:
            for label, know in (("plain", plain), ("principal", principal)):
                told = knowledge_file(Path(folder) / f"{label}.json", settings, know)
                run = _model2_points(settings, targets_head, {"from": str(told)})
                extra[label] = [r.measurement for r in run.records]
    ok = [m for m in measurements if m.ok]
    renders = [m.renders for m in ok]
    residuals = [abs(r) for m in ok for r in m.servo_residual_px]
    near = [m for m in ok if centre_row_offset_px(settings, m) <= CENTRE_ROW_BAND_PX]
    out.update(
        {
            "overall": error_figures(measurements),
            "near_centre_row": error_figures(near),
            "bands": {key: error_figures(ms) for key, ms in bands.items()},
            "renders_per_point_after_first": float(np.mean(renders[1:]))
            if len(renders) > 1
            else None,
            "servo_residual_px_mean": float(np.mean(residuals)) if residuals else None,
            "servo_residual_px_max": float(np.max(residuals)) if residuals else None,
            "wall_s_per_point": wall / max(len(measurements), 1),
            "render_s": tenth_render,
            "wall_per_point_over_render": wall / max(len(measurements), 1) / tenth_render,
        }
    )
    if calibrate:
        out["y_conditions"] = {
            "image_centre_rows (Table VI)": error_figures(extra["plain"]),
            "principal_rows_given (Table V)": error_figures(extra["principal"]),
            "extended_calibration": error_figures(measurements),
        }
    return out


#: The paper's camera imperfections, each switched off in turn for the error budget.
def _without(settings: HeadSettings, what: str) -> HeadSettings:
    def change(cam: CameraSettings) -> CameraSettings:
        if what == "distortion":
            return replace(cam, k1=0.0, k2=0.0)
        if what == "principal offset":
            return replace(cam, cx=None, cy=None)
        if what == "kx != ky":
            return replace(cam, ky=cam.kx)
        if what == "mount offsets":
            return replace(cam, mount_yaw_rad=0.0)
        raise ValueError(what)

    return replace(settings, cameras=tuple(change(c) for c in settings.cameras))  # type: ignore[arg-type]


IMPERFECTIONS = ("distortion", "principal offset", "kx != ky", "mount offsets")


def paper_error_budget(
    rng_seed: int,
    targets_per_band: int = 12,
    calibration_targets: int = 60,
    progress: Progress = quiet,
) -> dict[str, Any]:
    """x/z errors with the paper's cameras, and with each imperfection off in turn."""
    budget = {}
    for label, settings in [("all imperfections", paper_head())] + [
        (f"without {what}", _without(paper_head(), what)) for what in IMPERFECTIONS
    ]:
        progress(f"error budget: {label}")
        figures = model2_accuracy(
            settings,
            np.random.default_rng(rng_seed),
            targets_per_band=targets_per_band,
            calibrate=True,
            calibration_targets=calibration_targets,
        )
        budget[label] = {
            "near_centre_row": figures["near_centre_row"],
            "overall": figures["overall"],
            "calibration_error_rad": figures["calibration"]["error_rad"],
        }
    return budget


def chessboard_accuracy(
    settings: HeadSettings,
    knowledge: HeadKnowledge,
    distance_m: float = 0.85,
    corners: Sequence[int] | None = None,
) -> dict[str, Any]:
    """Square sides from the chessboard's measured cross points, mm, with and without v0/kx/ky.

    The chessboard scenario on the preset head ``settings``, its top-left inner
    corner ``distance_m`` ahead, told ``knowledge`` (then its initial directions only).
    """
    out: dict[str, Any] = {}
    head = preset_of(settings)
    with tempfile.TemporaryDirectory() as folder:
        for k, (label, know) in enumerate(
            (
                ("extended calibration", knowledge),
                ("offsets only", HeadKnowledge(alpha_e=knowledge.alpha_e)),
            )
        ):
            told = knowledge_file(Path(folder) / f"told_{k}.json", settings, know)
            doc = {
                "description": "The chessboard's squares from its measured cross points",
                "head": {"preset": head},
                "experiment": {"procedure": "chessboard", "calibration": {"from": str(told)}},
                "scene": {
                    "chessboard": {
                        "position_world_m": [-0.105, distance_m, 0.21 + 0.075],
                        "corners": "all" if corners is None else list(corners),
                    }
                },
            }
            result = run_scenario(scenario_from_document(doc, "chessboard_accuracy"))
            board: Any = result.experiment  # the chessboard procedure's result
            measurements = [r.measurement for r in result.records]
            widths, heights = 1000 * board.widths_m, 1000 * board.heights_m
            out[label] = {
                "corners_measured": board.corners_measured,
                "corners": len(measurements),
                "width_mean_mm": float(widths.mean()) if widths.size else None,
                "width_std_mm": float(widths.std()) if widths.size else None,
                "height_mean_mm": float(heights.mean()) if heights.size else None,
                "height_std_mm": float(heights.std()) if heights.size else None,
                "points": error_figures(measurements),
            }
    return out


def area_tally(
    objects_per_layout: int, layouts: Sequence[tuple[int, AreaComparison | None]]
) -> dict[str, Any]:
    """Eq. (12)'s score over layouts of ``objects_per_layout`` objects each.

    ``layouts``: per layout, the objects not seen in all four images and the
    comparison of the others (None: the reference was not fixated, nothing
    measured).  ``correct_pct`` counts every object placed, an unmeasured one
    as wrong; ``outside_margin_correct_pct`` is the subset more than the
    margin from a boundary (None when there is none).
    """
    agree_all = agree_outside = disagree_outside = inside = disagree_inside = 0
    missing = unmeasured = 0
    for not_seen, c in layouts:
        missing += not_seen
        if c is None:
            unmeasured += objects_per_layout - not_seen
            continue
        agree_all += int(np.sum(c.agree))
        inside += c.n_inside
        disagree_inside += c.n_disagree_inside
        disagree_outside += c.n_disagree_outside
        agree_outside += c.n_objects - c.n_inside - c.n_disagree_outside
    objects = objects_per_layout * len(layouts)
    outside = agree_outside + disagree_outside
    return {
        "objects": objects,
        "correct": agree_all,
        "correct_pct": 100.0 * agree_all / objects if objects else None,
        "not_seen_in_all_four_images": missing,
        "reference_not_fixated": unmeasured,
        "outside_margin": outside,
        "outside_margin_correct_pct": 100.0 * agree_outside / outside if outside else None,
        "within_2px_of_a_boundary": inside,
        "within_2px_disagreeing": disagree_inside,
    }


def relative_areas(
    rng: np.random.Generator,
    layouts: int = 9,
    progress: Progress = quiet,
    settings: HeadSettings | None = None,
) -> dict[str, Any]:
    """Eq. (12) on pixels against the geometric truth over random object layouts.

    Each layout keeps the paper's reference and scatters the six objects at
    0.8-1.9 m, |x/z| <= 0.3.  ``correct_pct`` is over every object placed: one
    not seen in all four images, or in a layout whose reference was not fixated,
    counts as wrong.  ``outside_margin_correct_pct`` is the subset more than 2 px
    from an area boundary, reported beside it.  ``settings``: the head (default:
    ideal cameras).
    """
    layout_runs: list[tuple[int, AreaComparison | None]] = []
    areas_seen: set[int] = set()
    renders = []
    settings = settings or HeadSettings()
    for layout in range(layouts):
        objects = []
        for name in names.RELATIVE_OBJECTS:
            z = rng.uniform(0.8, 1.9)
            p_head = [rng.uniform(-0.3, 0.3) * z, rng.uniform(-0.15, 0.1) * z, z]
            objects.append({"body": name, "position_head_m": [float(v) for v in p_head]})
        doc = {
            "description": "Eq. (12) on one random layout of the six objects",
            "seed": settings.seed,
            "head": {"preset": preset_of(settings)},
            "experiment": {"procedure": "relative_positioning"},
            "scene": {"objects": objects},
        }
        run: Any = run_scenario(scenario_from_document(doc, "relative_layout")).experiment
        progress(f"relative positioning: layout {layout + 1}/{layouts}")
        renders.append(run.renders)
        layout_runs.append((len(run.missing), _comparison(run)))
        if run.margin_threshold_px is not None:
            areas_seen.update(o.true_area for o in run.objects if o.true_area)
    return {
        **area_tally(len(names.RELATIVE_OBJECTS), layout_runs),
        "distinct_true_areas": sorted(areas_seen),
        "renders_per_layout": float(np.mean(renders)),
    }


def _comparison(run: Any) -> AreaComparison | None:
    """Eq. (12)'s comparison over the objects a relative-positioning result saw in all
    four images (None: the reference was not fixated, nothing compared)."""
    if run.margin_threshold_px is None:
        return None
    seen = [o for o in run.objects if o.name not in run.missing]
    return tally_areas(
        [o.margin_px for o in seen], [o.agree for o in seen], run.margin_threshold_px
    )


SERVO_CASES = {
    "focal 0.5x": CameraSettings().with_zoom(0.5),
    "focal 0.75x": CameraSettings().with_zoom(0.75),
    "focal 1.5x": CameraSettings().with_zoom(1.5),
    "focal 2x": CameraSettings().with_zoom(2.0),
    "principal -40 px": CameraSettings(cx=279.5, cy=199.5),
    "principal +40 px": CameraSettings(cx=359.5, cy=279.5),
    "paper camera 1": paper_head().cameras[0],
}


def servo_robustness(
    rng: np.random.Generator, points: int = 8, progress: Progress = quiet
) -> dict[str, Any]:
    """The servo, told nothing, over focal lengths 0.5x-2x and shifted principal points."""
    out = {}
    for label, cam in SERVO_CASES.items():
        targets_head = random_targets_head(rng, points, (0.4, 1.4), vertical=(-0.1, 0.1))
        doc = {
            "description": f"The servo, told nothing, with cameras {label}",
            "experiment": {"procedure": "model2"},
            "scene": {
                "targets": [
                    {"name": f"point_{k}", "position_head_m": [float(v) for v in p]}
                    for k, p in enumerate(targets_head)
                ]
            },
        }
        settings = HeadSettings(cameras=(cam, cam))
        result = run_scenario(scenario_with_head(doc, "servo_robustness", settings))
        ms = [r.measurement for r in result.records]
        progress(f"servo: {label}")
        ok = [m for m in ms if m.ok]
        residuals = np.array([abs(r) for m in ok for r in m.servo_residual_px])
        out[label] = {
            "converged": f"{len(ok)}/{len(ms)}",
            "renders_per_point_after_first": float(np.mean([m.renders for m in ok[1:]]))
            if len(ok) > 1
            else None,
            "residual_px_mean": float(residuals.mean()) if residuals.size else None,
            "residual_px_max": float(residuals.max()) if residuals.size else None,
            "half_step_px": 0.5 * cam.kx * HeadSettings().encoder_resolution_rad,
            "rms_3d_pct_depth": error_figures(ms).get("rms_3d_pct_depth"),
        }
    return out


def _circle_world_m(t: float) -> np.ndarray:
    """The tracking benchmark's path at ``t``: a loop 0.8 m ahead (W, m)."""
    return np.array([0.15 * np.cos(t), 0.8 + 0.15 * np.sin(t), 0.25 + 0.08 * np.sin(2 * t)])


def tracking_scenario(fixations: int = 12) -> Scenario:
    """The red marker on :func:`_circle_world_m` over one turn, fixated ``fixations`` times
    with Model 1 (neck and eyes) by the ideal head, told nothing: the path is sampled at
    the fixation times, so the scenario's piecewise-linear target is on the circle there."""
    times = np.linspace(0, 2 * np.pi, fixations)
    doc = {
        "description": "Model 1 follows a marker on a circle 0.8 m ahead (ideal head)",
        "experiment": {"procedure": "tracking"},
        "scene": {
            "moving_target": {
                "body": "marker_red",
                "waypoints_world_m": [[float(v) for v in _circle_world_m(t)] for t in times],
                "duration_s": float(times[-1]),
                "steps": fixations,
            }
        },
    }
    return scenario_from_document(doc, "tracking_circle")


def tracking_accuracy(fixations: int = 12) -> dict[str, Any]:
    """A target on a circle 0.8 m ahead, followed with Model 1 (neck and eyes)."""
    result = run_scenario(tracking_scenario(fixations))
    measurements = [r.measurement for r in result.records]
    experiment: Any = result.experiment  # the tracking procedure's result
    errors = experiment.errors_world_m
    renders = [m.renders for m in measurements]
    return {
        "fixations": fixations,
        "ok": sum(m.ok for m in measurements),
        "error_world_mm_rms": float(1000 * np.sqrt(np.nanmean(errors**2))),
        "error_world_mm_max": float(1000 * np.nanmax(errors)),
        "renders_first": renders[0],
        "renders_per_fixation_after_first": float(np.mean(renders[1:])),
    }
