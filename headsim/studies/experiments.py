"""Seeded accuracy experiments over the procedures: the figures behind the benchmarks.

Each function builds its own simulators, runs a procedure on seeded random
targets and returns plain figures (dicts of floats and lists) ready for JSON.
Errors are estimate minus truth in the head frame H; "% of depth" divides by
the true z_h.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, cast

import numpy as np

from headsim.active.calibration import calibrate_head
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, Measurement, body_target
from headsim.active.model2 import measure_model2
from headsim.active.placement import calibration_layout
from headsim.active.servo_types import Detector
from headsim.estimators.areas import AreaComparison
from headsim.procedures.relative import relative_positioning
from headsim.run.runner import run_scenario
from headsim.scenario.loading import scenario_from_document
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim
from headsim.studies.scenario_runs import knowledge_file, preset_of
from headsim.studies.targets import place_in_head, random_targets_head, visible_vertical_range
from headsim.vision.crosses import find_cross_point
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))
BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))
DEPTH_BANDS_M = ((0.3, 0.6), (0.6, 1.0), (1.0, 1.5))
#: Rows within this many px of the image centre row count as "near the centre row".
CENTRE_ROW_BAND_PX = 100.0

Progress = Callable[[str], None]


def _quiet(_: str) -> None:
    pass


def render_time_s(sim: HeadSim, repeats: int = 10) -> float:
    """Median wall time of one render of camera 1 in ``sim``, s (not counted as work)."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        sim.render(1)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def centre_row_offset_px(sim: HeadSim, m: Measurement) -> float:
    """Largest |v - centre row| of the target over both cameras' y images, px."""
    return max(
        abs(m.details["v11_px"] - sim.camera_settings(1).image_centre[1]),
        abs(m.details["v21_px"] - sim.camera_settings(2).image_centre[1]),
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


def model2_accuracy(
    settings: HeadSettings,
    rng: np.random.Generator,
    *,
    targets_per_band: int = 20,
    calibrate: bool = False,
    calibration_targets: int = 60,
    vertical: tuple[float, float] | None = None,
    progress: Progress = _quiet,
) -> dict[str, Any]:
    """Model 2 over the depth bands, after Sec. V calibration if ``calibrate``.

    Returns errors per band and overall, split by rows near the centre row,
    renders per point, servo residuals, wall time per point and per render,
    the calibration's recovered offsets beside the truth, and y errors under
    three conditions: image-centre rows (Table VI), principal rows given
    (Table V) and the extended calibration.
    """
    out: dict[str, Any] = {}
    vertical = vertical or visible_vertical_range(settings)
    with HeadSim("default", settings) as sim:
        servo = EyeServo(sim)
        knowledge = HeadKnowledge()
        if calibrate:
            progress("calibrating the initial directions")
            run = calibrate_head(
                sim,
                servo,
                BALL,
                names.CALIBRATION_BALL,
                calibration_layout(sim.stereo_views(), rng, calibration_targets),
            )
            knowledge = run.knowledge
            out["calibration"] = {
                "alpha_e_rad": list(run.fit.alpha_e),
                "truth_alpha_e_rad": list(run.truth_alpha_e),
                "error_rad": [float(e) for e in run.alpha_e_error],
                "std_error_rad": [float(s) for s in run.fit.std_errors],
                "samples": run.samples,
                "renders": run.renders,
                "v0_px": [v.v0 for v in run.vertical] if run.vertical else None,
                "kx_over_ky": [v.kx_over_ky for v in run.vertical] if run.vertical else None,
            }
        plain = HeadKnowledge(alpha_e=knowledge.alpha_e)
        principal = replace(plain, v0=tuple(c.principal[1] for c in settings.cameras))  # type: ignore[arg-type]
        tenth_render = render_time_s(sim)
        measurements: list[Measurement] = []
        bands: dict[str, list[Measurement]] = {}
        extra: dict[str, list[Measurement]] = {"plain": [], "principal": []}
        start = time.perf_counter()
        for low, high in DEPTH_BANDS_M:
            key = f"{low:.1f}-{high:.1f} m"
            bands[key] = []
            for p_head in random_targets_head(
                rng, targets_per_band, (low, high), vertical=vertical
            ):
                place_in_head(sim, "marker_red", p_head)
                m = measure_model2(sim, servo, RED, knowledge)
                bands[key].append(m)
                measurements.append(m)
                progress(f"model 2: {len(measurements)} points")
        wall = time.perf_counter() - start
        if calibrate:  # the same targets with less knowledge, for the y budget
            for m in measurements:
                sim.set_body_pose("marker_red", m.truth_world_m)
                extra["plain"].append(measure_model2(sim, servo, RED, plain))
                extra["principal"].append(measure_model2(sim, servo, RED, principal))
    ok = [m for m in measurements if m.ok]
    renders = [m.renders for m in ok]
    residuals = [abs(r) for m in ok for r in m.servo_residual_px]
    near = [m for m in ok if centre_row_offset_px(sim, m) <= CENTRE_ROW_BAND_PX]
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
    progress: Progress = _quiet,
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
    progress: Progress = _quiet,
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
    with HeadSim("blocks", settings) as sim:
        servo = EyeServo(sim)
        # Status and uv are all the servo reads of a cross point (never windowed).
        reference = body_target(names.BLOCKS, cast(Detector, find_cross_point))
        for layout in range(layouts):
            for name in names.RELATIVE_OBJECTS:
                z = rng.uniform(0.8, 1.9)
                p_head = np.array([rng.uniform(-0.3, 0.3) * z, rng.uniform(-0.15, 0.1) * z, z])
                place_in_head(sim, name, p_head)
            run = relative_positioning(sim, servo, reference, names.RELATIVE_OBJECT_COLOURS)
            progress(f"relative positioning: layout {layout + 1}/{layouts}")
            renders.append(run.renders)
            layout_runs.append((len(run.missing), run.comparison))
            if run.comparison is not None:
                areas_seen.update(a for a in run.true_areas.values() if a)
    return {
        **area_tally(len(names.RELATIVE_OBJECTS), layout_runs),
        "distinct_true_areas": sorted(areas_seen),
        "renders_per_layout": float(np.mean(renders)),
    }


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
    rng: np.random.Generator, points: int = 8, progress: Progress = _quiet
) -> dict[str, Any]:
    """The servo, told nothing, over focal lengths 0.5x-2x and shifted principal points."""
    out = {}
    for label, cam in SERVO_CASES.items():
        with HeadSim("default", HeadSettings(cameras=(cam, cam))) as sim:
            servo = EyeServo(sim)
            ms = []
            for p_head in random_targets_head(rng, points, (0.4, 1.4), vertical=(-0.1, 0.1)):
                place_in_head(sim, "marker_red", p_head)
                ms.append(measure_model2(sim, servo, RED))
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
