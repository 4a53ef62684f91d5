"""What each key of results.json means: the one source the reference page is made from.

:data:`RESULTS_FIELDS` maps a key's path to its meaning: ``a.b`` a key of a
table, ``a[].b`` a key of each entry of a list, ``a.*`` each key of a table
whose keys are data (a knowledge, a phase).  A path listed without any of its
children is described as a whole (its keys are not listed one by one).
:data:`EXPERIMENT_FIELDS` gives each procedure's ``experiment`` keys the same
way, relative to ``experiment``.  :func:`undocumented` and
:func:`documented_paths` compare a real results.json with both; the
documentation hook (``tools/docs_pages.py``) writes the page from them.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

_COUNTS = "full frames, windows, retakes and previews"

#: Every key of results.json outside ``experiment``'s procedure keys, in the order written.
RESULTS_FIELDS: dict[str, str] = {
    "schema": '`"headsim.results/2"` (2: one render count, every image drawn, previews '
    "included, in `render_counts`)",
    "scenario": "the scenario as run: its file, its procedure and its checked scene",
    "scenario.name": "the scenario's name",
    "scenario.file": "its file's name",
    "scenario.description": "its `description`",
    "scenario.procedure": "its `[experiment] procedure`",
    "scenario.fast": "whether the fast variant ran",
    "scenario.preset": "the head preset (`ideal`, `paper`, `realistic`)",
    "scenario.scene": "the checked scene: every placement in W, random ones drawn",
    "scenario.scene.scene": "the MJCF scene",
    "scenario.scene.targets": "the targets to measure, each a placement in W",
    "scenario.scene.chessboard": "the chessboard's placement, or `null`",
    "scenario.scene.corners": "the chessboard's inner corners (columns, rows), or `null`",
    "scenario.scene.blocks": "the crossed blocks' placement, or `null`",
    "scenario.scene.objects": "the relative-positioning objects' placements",
    "scenario.scene.parked": "the bodies parked out of sight",
    "scenario.scene.moving": "the moving target's path, or `null`",
    "scenario.scene.pursuit": "the live pursuit's target and path, or `null`",
    "scenario.scene.room": "the textured room (`[scene.room]`): its seed, surface texture, "
    "table and walls, every object (clutter drawn from the seed included) and the light; "
    "`null`: none",
    "scenario.scene.surface_targets": "`[scene.room] targets` and its keys (`count`, "
    "`depth_m`, `lateral`, `vertical`, `click_error_px`, `band_px`, `listed`, `targets_as`); "
    "`null`: none",
    "scenario.scene.acceptance": "how the targets came to be measured (`null`: a procedure "
    "without targets)",
    "scenario.scene.acceptance.within": "`[scene.random_targets] within` (`box` or `reach`; "
    "`null`: no random targets)",
    "scenario.scene.acceptance.listed": "the `[[scene.targets]]` entries",
    "scenario.scene.acceptance.drawn": "random draws made, refused ones included",
    "scenario.scene.acceptance.refused": "draws the reach check refused, by reason (`depth`, "
    "`eye_range`, `neck_range`, `neck_offset`, `not_in_any_view`, `occluded`, `start_view`)",
    "scenario.scene.acceptance.accepted": "the targets measured, listed and drawn",
    "scenario.scene.acceptance.outside_start_view": "the names of the accepted targets the "
    "start pose does not show whole to both cameras",
    "scenario.experiment": "the `[experiment]` options as read (the servo's included)",
    "seed": "the seed used",
    "status": '`"ok"` or `"failed"`',
    "failures": "one line per failed measurement (or calibration, or object not seen)",
    "software": "versions of headsim, Python, MuJoCo, NumPy, SciPy, OpenCV, rerun-sdk",
    "settings": "the true head",
    "settings.baseline_m": "the baseline, m",
    "settings.neck_d1_m": "the neck's d1, m",
    "settings.neck_a2_m": "the neck's a2, m",
    "settings.encoder_resolution_rad": "one encoder count, rad",
    "settings.cameras": "each camera's settings (`kx`, `ky`, `cx`, `cy`, `width`, `height`, "
    "`k1`, `k2`, `noise_std`, `mount_yaw_rad`, `mount_pitch_rad`, `mount_roll_rad`, "
    "`nodal_offset_m`, `side_offset_m`, `eye_axis_tilt_rad`)",
    "settings.seed": "the seed of the head's own draws",
    "settings.belief": "what the head was told it is, as given (`null`: the truth)",
    "settings.backlash_rad": "play of every joint's gearing, rad",
    "settings.count_error": "whether the true angle lies anywhere within the count read, not on it",
    "settings.render": "the rendering fidelity: `offsamples`, `supersample`",
    "settings.head": "the head, only when it is not the paper's (absent: the paper's head)",
    "settings.head.name": "its name: a shipped head's, or the MJCF file's stem",
    "settings.head.path": "its MJCF file",
    "settings.head.mapping": "the names headsim uses in it (the scenario's `[head.mapping]`): "
    "`head_body`, `neck_yaw`, `neck_pitch`, `eyes`, `left_eye`, `right_eye`, `cameras`, "
    "`neck_roll`, `eye_tilt`, `version`, `vergence` (`null`: none)",
    "settings.settle_mode": "how the servo waits for the joints to settle",
    "belief": "what the head believed and measured with",
    "belief.baseline_m": "the believed baseline, m",
    "belief.neck_d1_m": "the believed neck d1, m",
    "belief.neck_a2_m": "the believed neck a2, m",
    "belief.nodal_offset_m": "the believed nodal offset, m (recorded; no estimate uses it, "
    "since it acts only through the goal column's angle off the optical axis)",
    "belief.side_offset_m": "the believed side offset, m",
    "belief.sources": "where each believed quantity above came from: `design` (the head's "
    "design), `preset` (the realistic preset's own belief), `file` (the scenario's "
    "`[belief]`), `given` (a `HeadBelief` given in Python), or `truth` (equal to the true "
    "head's, which the scenario changed in `[head]` and the belief followed)",
    "render_counts": "every image the simulator drew, each one a render",
    "render_counts.*": "one phase: `calibration`, `experiment` or `overall`",
    "render_counts.*.images": "full frames",
    "render_counts.*.windows": "windows",
    "render_counts.*.retakes": "windows retaken whole at the same instant",
    "render_counts.*.previews": "binned previews",
    "render_counts.*.total": f"all of them ({_COUNTS})",
    "render_counts.*.in_measurements": "`experiment` only: the sum of its measurements' `renders`",
    "render_counts.*.outside_measurements": "`experiment` only: renders of the procedure that "
    "belong to no measurement",
    "rendered_frames": "pixels rendered, in full frames (a window counts its share; also in "
    "`timing.json`)",
    "rendered_frames.calibration": "during the calibration",
    "rendered_frames.experiment": "during the experiment",
    "rendered_frames.total": "both",
    "calibration": "`null`, or the Sec. V calibration (a calibration file holds the same block)",
    "calibration.status": "`ok`, or its failure's cause (too few positions seen because ..., "
    "a degenerate layout because ..., no vertical spread for the extended fit)",
    "calibration.targets": "layout positions",
    "calibration.fixated": "positions fixated",
    "calibration.positions": "each layout position's `status` and `failure`, as a measurement's",
    "calibration.render_counts": "as the run's, for the calibration (in `from`, a stored "
    "calibration's, `null` for one written before schema 2)",
    "calibration.layout": "the positions: `kind` (a layout, or `given`), `near_fraction`, "
    "`depth_m`, `lateral`, `vertical`, `positions_world_m`",
    "calibration.depth_noise_m": "error of the tape-measured depth of each ball, m",
    "calibration.position_noise_m": "error of every measured coordinate of every ball, m",
    "calibration.lines_of_sight_fit": "whether the extended line-of-sight fit was asked for",
    "calibration.extended": "whether the extended fit (v0, kx/ky) ran",
    "calibration.alpha_e_rad": "the fitted alpha_e of each camera, rad",
    "calibration.alpha_e_std_rad": "its 1-sigma, rad",
    "calibration.alpha_e_covariance_rad2": "its covariance, rad^2",
    "calibration.alpha_e_truth_rad": "the true alpha_e, rad",
    "calibration.alpha_e_error_rad": "fitted minus true, rad",
    "calibration.alpha_e_paper_rad": "the paper's, rad",
    "calibration.converged": "whether the fit converged",
    "calibration.depth_residual_rms_m": "RMS of the fit's depth residuals, m",
    "calibration.vertical_reference": "`v0_px`, `kx_over_ky` with their `_std` and `_truth` "
    "(`null`: not extended)",
    "calibration.lines_of_sight": "the extended fit: `alpha_e_rad`, `offset_m`, `std_errors`, "
    "`covariance` of (alpha_e1, alpha_e2, s1, s2), `offset_truth_m`, `effective_baseline_m` "
    "with `_std_m` and `_truth_m`, `separable`, `message` (`null`: not asked for)",
    "calibration.knowledge": "what the head measured with afterwards (`los_offset_m` included)",
    "measurements": "one entry per measurement, in order",
    "measurements[].name": "the target (`corner_i_j` for chessboard corners, `blocks` for the "
    "cross point)",
    "measurements[].method": "`model2`, `model1` or `fixation`",
    "measurements[].status": '`"ok"`, or why it failed (`"Ca2 at step 1: target lost (and at '
    '12 eye angles searched)"`, ...)',
    "measurements[].failure": "`null`, or the cause: `cause` (`lost`, `cut`, `occluded`, "
    "`low texture`, `ambiguous`, `joint limit`, `iteration limit`, `estimator`), `stage` (`step 1`, `step 2`, `fixation`, "
    "`estimate`), `camera` (1, 2 or `null`), `detail`",
    "measurements[].knowledge": 'what the head knew: `"none"` or `"calibrated"`',
    "measurements[].step": "its step in the recording",
    "measurements[].time_s": "tracking: the target's time, s; else `null`",
    "measurements[].estimate_head_m": "the estimate in H, m",
    "measurements[].truth_head_m": "the truth in H, m",
    "measurements[].estimate_world_m": "the estimate in W through eq. (3) and the neck encoders, m",
    "measurements[].truth_world_m": "the truth in W, m",
    "measurements[].error_head_m": "estimate minus truth in H, m",
    "measurements[].error_m": "its length, m",
    "measurements[].depth_m": "the true depth z_h, m",
    "measurements[].error_pct_of_depth": "`error_m` in % of `depth_m`",
    "measurements[].covariance_head_m2": "first-order covariance of the estimate in H, m^2",
    "measurements[].renders": f"renders this measurement took ({_COUNTS})",
    "measurements[].search_renders": "renders it spent finding a lost target again (in `renders`)",
    "measurements[].scan_renders": "renders of `search_renders` spent scanning the joints' "
    "ranges for a target the head's pose did not show",
    "measurements[].servo_residual_px": "each servo's final image offset from its goal, px",
    "measurements[].details": "angles and pixels used (`alpha1_rad`, `u11_px`, ...)",
    "measurements[].fixation": "a markerless target's landing truth (`[scene.room] targets`; "
    "`null`: a marker's): each eye's goal ray at its true pose where its servo converged (Model "
    "2: camera 1 at step 1, camera 2 at step 2; Model 1: both at the fixation), cast into the "
    "scene; truth, never told the head",
    "measurements[].fixation.vergence_error_deg": "angle between eye 2's goal ray and the "
    "direction from eye 2 to the point eye 1 landed on, degrees (`null`: the measurement failed)",
    "measurements[].fixation.error_deg": "each eye's goal ray against the direction to the "
    "intended target, degrees",
    "measurements[].fixation.error_m": "each eye's landed point's distance from the intended "
    "target, m",
    "measurements[].fixation.landed": 'the object each eye\'s ray hit (`""`: none or not converged)',
    "measurements[].fixation.landed_world_m": "each eye's landed point in W, m (`null`: none)",
    "measurements[].fixation.click_error_px": "|clicked - true| of the click in camera 1's "
    "image the head was told, px",
    "measurements[].fixation.image_error_px": "each eye's look at its fixation: |where its "
    "image said the clicked surface point is - its true projection|, px (eye 1: the tracker's "
    "drift; eye 2: the correspondence error; the click's error apart)",
    "measurements[].fixation.match_sigma_px": "the location spread the matched template's "
    "texture allows at the image noise (Cramer-Rao, one axis), px: the theory's correspondence "
    "noise",
    "measurements[].fixation.match_error_px": "camera 2's last confident look: |where its "
    "match put the clicked point - its true projection|, px, whatever the measurement's "
    "outcome (`null`: no confident match)",
    "measurements[].fixation.wrong_match": "that error exceeds the false-fixation limit seen "
    "from camera 2 (`false_fixation_limit_m` / depth x camera 2's focal length): a confident "
    "match on the wrong point, counted also where the measurement then failed",
    "measurements[].fixation.match_score": "camera 2's last confident correspondence (else its "
    "last): peak NCC",
    "measurements[].fixation.match_ambiguity": "its second-best peak over the best",
    "measurements[].fixation.match_status": "its status (`ok`, `low texture`, `ambiguous`, "
    "`occluded`, `lost`)",
    "measurements[].fixation.false_fixation": "the measurement is ok but an eye landed farther "
    "than `false_fixation_limit_m` from the target (or on nothing)",
    "measurements[].fixation.false_fixation_limit_m": "that distance: 1 % of the target's depth, "
    "at least 5 mm",
    "summary": "the measurements' statistics, per knowledge",
    "summary.*": 'one knowledge (`"none"`, `"calibrated"`)',
    "summary.*.count": "measurements",
    "summary.*.ok": "measurements that succeeded",
    "summary.*.failed": "measurements that failed",
    "summary.*.error_m_mean": "mean 3-D error, m",
    "summary.*.error_m_max": "largest 3-D error, m",
    "summary.*.error_pct_of_depth_mean": "mean error, % of depth",
    "summary.*.error_pct_of_depth_max": "largest error, % of depth",
    "summary.*.renders_per_point": "renders per measurement",
    "summary.*.servo_residual_px_max": "largest servo residual, px",
    "summary.*.searched": "measurements that needed a search",
    "summary.*.search_renders": "their search renders",
    "summary.*.failure_causes": "cause -> count",
    "summary.*.error_pct_of_depth_rms": "RMS error of all targets, % of depth",
    "summary.*.by_depth": "per depth band 0-0.6, 0.6-1, >= 1 m",
    "summary.*.by_depth[].band": "the band",
    "summary.*.by_depth[].count": "measurements in it",
    "summary.*.by_depth[].asked": "targets whose true depth lies in it, the failed ones included",
    "summary.*.by_depth[].error_pct_of_depth_rms": "their RMS error, % of depth",
    "summary.*.scanned": "measurements that scanned for a target the start pose did not show",
    "summary.*.scan_renders": "their scan renders",
    "summary.*.outside_start_view": "the targets the start pose did not show whole to both "
    "cameras (the field's edge, a labelled subset)",
    "summary.*.outside_start_view.count": "how many",
    "summary.*.outside_start_view.ok": "how many succeeded",
    "summary.*.outside_start_view.error_pct_of_depth_rms": "their RMS error, % of depth",
    "experiment": "the procedure's own results (below)",
    "experiment.procedure": "the procedure's name",
}

_NONE: dict[str, str] = {}

#: Each procedure's ``experiment`` keys beside ``procedure``, relative to ``experiment``.
#: ``experiment`` keys a procedure writes only when it failed.
FAILED_ONLY = frozenset({"reason"})

#: Model 2's and Model 1's keys with markerless targets (none with markers).
_SURFACE: dict[str, str] = {
    "surface_targets": "how the markerless targets were drawn and how they landed",
    "surface_targets.asked": "targets asked for (`[scene.room] targets`)",
    "surface_targets.listed": "of them, those listed (`[[scene.room.targets]]`), measured first",
    "surface_targets.measured_as": "`surface` (by correlation) or `markers` (a marker put at "
    "each point: the marker twin, `[scene.room] targets_as`)",
    "surface_targets.drawn": "draws made, refused ones included",
    "surface_targets.refused": "draws refused and drawn again, by cause (`no_surface`, `depth`, "
    "`occluded`, `start_view`, `reach`)",
    "surface_targets.false_fixation_limit": "the rule of a false fixation",
    "surface_targets.targets": "each target: `name`, the `body` it lies on, `point_world_m`, "
    "its `texture_class` (`rich`, `low`, `repetitive`, `occluded`: from truth at placement)",
    "surface_targets.false_fixations": "measurements ok with an eye landed off the target",
    "surface_targets.wrong_matches": "targets whose camera 2 made a confident match on the "
    "wrong point (`wrong_match`)",
    "surface_targets.wrong_matches_failed": "of those, the ones whose measurement then failed "
    "(not false fixations: counted here, not hidden)",
    "surface_targets.vergence_error_deg_median": "median vergence error of the fixations, degrees",
    "surface_targets.vergence_error_deg_rms": "their RMS, degrees",
    "surface_targets.by_texture": "per texture class (`rich`: pink noise, `low`, `repetitive`: "
    "gratings, stripes, checks; `occluded`: part of either camera's template window hidden "
    "from the other at the start pose), always all four",
    "surface_targets.by_texture[].texture_class": "the class",
    "surface_targets.by_texture[].asked": "targets placed in it, the failed ones included",
    "surface_targets.by_texture[].measured": "those measured (ok)",
    "surface_targets.by_texture[].error_pct_of_depth_rms": "their 3-D error RMS, % of depth",
    "surface_targets.by_texture[].vergence_error_deg_median": "median vergence error, degrees",
    "surface_targets.by_texture[].vergence_error_deg_rms": "its RMS, degrees",
    "surface_targets.by_texture[].false_fixations": "measurements ok with an eye landed off",
    "surface_targets.by_texture[].wrong_matches": "confident matches on the wrong point",
    "surface_targets.by_texture[].failure_causes": "failures by cause",
    "surface_targets.by_texture[].renders_per_point": "renders per target asked",
}

#: ``experiment`` keys written only with markerless targets (``[scene.room] targets``).
MARKERLESS_ONLY = frozenset(_SURFACE)

EXPERIMENT_FIELDS: dict[str, dict[str, str]] = {
    "model2": _SURFACE,
    "model1": _SURFACE,
    "fixation": _SURFACE,
    "calibration": {
        "check_targets": "each check target, before and after the calibration",
        "check_targets[].name": "the target",
        "check_targets[].error_m_uncalibrated": "its 3-D error with what the head was told, m "
        "(NaN: failed)",
        "check_targets[].error_m_calibrated": "its 3-D error calibrated, m (NaN: failed)",
    },
    "chessboard": {
        "pattern": "inner corners (columns, rows)",
        "square_m": "the squares' side, m",
        "corners": "inner corners",
        "corners_measured": "corners measured",
        "widths_m": "each square's measured width, m",
        "heights_m": "each square's measured height, m",
        "true_widths_m": "their true widths, m",
        "true_heights_m": "their true heights, m",
        "width_mean_m": "mean width, m",
        "width_std_m": "its std, m",
        "height_mean_m": "mean height, m",
        "height_std_m": "its std, m",
        "side_mean_m": "mean of all sides, m",
        "side_std_m": "its std, m",
        "paper": "Tables III/IV's square side",
        "paper.side_mean_m": "the paper's mean side, m (0.0303)",
        "paper.side_std_m": "the paper's std, m (0.000677)",
    },
    "relative_positioning": {
        "alpha1_rad": "the first fixation's encoder reading, rad",
        "alpha2_rad": "the second fixation's encoder reading, rad",
        "objects": "each object",
        "objects[].name": "its body",
        "objects[].colour": "its colour",
        "objects[].area": "its measured area S1..S12 (0: none)",
        "objects[].true_area": "its true area",
        "objects[].agree": "whether they agree",
        "objects[].margin_px": "the area test's margin for it, px (NaN: not compared)",
        "objects[].gain_area": "its area by the gain-normalised test",
        "objects[].gain_agree": "whether that agrees with the truth",
        "objects[].columns_px": "u11, u12, u21, u22, px",
        "objects[].position_head_m": "its true position in H, m",
        "missing": "objects not seen in all four images",
        "agree": "objects whose area agrees",
        "disagree_outside_margin": "disagreements outside the margin (`null`: no threshold)",
        "gain_agree": "agreements by the gain-normalised test",
        "gain_disagree_outside_margin": "its disagreements outside the margin",
        "margin_threshold_px": "the margin, px (`null`: none)",
        "renders": "renders of both fixations",
        "paper": "Sec. VI-C's `alpha1_rad`, `alpha2_rad` and `objects`",
        "paper.alpha1_rad": "the paper's first fixation angle, rad",
        "paper.alpha2_rad": "the paper's second fixation angle, rad",
        "paper.objects": "the paper's number of objects",
    },
    "stereo": {
        "poses": "board poses rendered",
        "views": "board views kept (the whole board found in both images)",
        "renders": "renders of the board views",
        "corner_rms_px": "detected corners against their true projections, RMS, px",
        "corner_max_px": "the same, largest, px",
        "cameras": "each camera's parameters (`fx`, `fy`, `cx`, `cy`, `k1`, `k2`): `truth`, `mono` (calibrateCamera) and `stereo` (stereoCalibrate)",
        "stereo_rms_px": "stereoCalibrate's reprojection RMS, px",
        "baseline_m": "the calibrated baseline, |t|, m",
        "true_baseline_m": "the true baseline, m",
        "t_m": "camera 2 from camera 1: the calibrated translation, m",
        "true_t_m": "the true translation, m",
        "r": "the calibrated rotation (3 x 3)",
        "true_r": "the true rotation (3 x 3)",
        "rotation_error_rad": "angle between the calibrated and the true rotation, rad",
        "max_rms_px": "the larger camera's reprojection RMS, px (acceptance: <= 0.2)",
        "max_abs_focal_error_pct": "the largest focal-length error against the truth, % (acceptance: <= 0.5)",
        "passed": "both acceptance figures met",
        "head_frames": "each way of placing camera 1 in H (`label`, `rotation_error_rad`, `translation_error_m`, `max_error_m`, `max_error_pct_depth`, `mean_error_pct_depth`)",
        "targets": "each target (`name`, `status`, `truth_head_m`, `estimate_head_m`, `estimate_world_m`, `uv1_px`, `uv2_px`), m, px",
        "reason": "why the pair was not calibrated (only then, beside `poses`)",
    },
    "zoom_fixed_points": {
        "zoom": "the focal length ratio of the second images",
        "views": "board poses whose corners were found at both focal lengths",
        "renders": "renders of the board at both focal lengths",
        "fixed_point_px": "each camera's fixed point (u, v), px",
        "truth_px": "each camera's principal point (cx, cy), px",
        "error_px": "each camera's fixed point minus its principal point, px",
        "std_px": "each camera's standard errors of (u, v), px",
        "scale": "each camera's fitted scale f' / f",
        "residual_rms_px": "each camera's RMS distance of the zoomed corners from the fit, px",
        "points": "each camera's matched corners",
        "reason": "why the fixed points were not found (only then)",
    },
    "tracking": {
        "times_s": "each fixation's time, s",
        "waypoints_world_m": "the path's waypoints in W, m",
        "errors_world_m": "each fixation's error in W, m",
        "renders_first": "renders of the first fixation",
        "renders_after_mean": "mean renders per fixation after it",
    },
    "pursuit": {
        "pursuit": "the pursuit spec as run (`path_kind`, `duration_s`, `frame_rate_hz`, "
        "`latency_frames`, `exposure_s`, `blur_subframes`, `mode`, `predictor`, `saccade`, ...)",
        "frames": "frames run",
        "frames_present": "frames on which the target was present",
        "frames_lost": "frames the target was lost",
        "losses": "times it was lost",
        "reacquisitions": "times it was found again",
        "saccades": "saccades made",
        "time_to_fixation_s": "time to the first fixation, s",
        "lag_s": "the gaze's lag behind the target, s",
        "offset_rms_px": "RMS image offset from the goal, px",
        "position_rms_m": "RMS position error in W along the path, m",
        "position_rms_pct_of_depth": "the same, % of depth",
        "position_max_m": "largest position error, m",
        "ended": "why the loop ended",
        "vergence_error_median_deg": "median vergence error over the frames that found the "
        "target (eye 2's goal ray against where eye 1's truly landed), deg",
        "vergence_error_rms_deg": "the same, RMS, deg",
        "per_frame": "each frame: `time_s`, `found`, `offsets_px`, `encoders_rad`, "
        "`estimate_world_m`, `truth_world_m`, `error_m`, `vergence_error_deg`",
    },
}


def _child(fields: Mapping[str, str], parent: str, key: str) -> str | None:
    """The documented path of ``key`` under ``parent`` (a listed key, else ``parent.*``)."""
    named = f"{parent}.{key}" if parent else key
    if named in fields:
        return named
    wildcard = f"{parent}.*"
    return wildcard if parent and wildcard in fields else None


def _opens(fields: Mapping[str, str], path: str) -> bool:
    """Whether ``path``'s keys are listed one by one."""
    return any(p.startswith((f"{path}.", f"{path}[]")) for p in fields)


def _walk(value: Any, path: str, fields: Mapping[str, str]) -> Iterator[tuple[str, str | None]]:
    """(path, documented path or None) of every key in a table whose keys are listed."""
    if isinstance(value, list):
        for item in value:
            yield from _walk(item, f"{path}[]", fields)
        return
    if not isinstance(value, dict) or not (path == "" or _opens(fields, path)):
        return
    for key, item in value.items():
        found = f"{path}.{key}" if path else key
        documented = _child(fields, path, key)
        yield found, documented
        if documented is not None:
            yield from _walk(item, documented, fields)


def _experiment_fields(results: Mapping[str, Any]) -> dict[str, str]:
    procedure = results.get("experiment", {}).get("procedure")
    return {f"experiment.{k}": v for k, v in EXPERIMENT_FIELDS.get(procedure, {}).items()}


def _pairs(results: Mapping[str, Any]) -> list[tuple[str, str | None]]:
    fields = {**RESULTS_FIELDS, **_experiment_fields(results)}
    return list(_walk(dict(results), "", fields))


def undocumented(results: Mapping[str, Any]) -> list[str]:
    """Keys of a results.json document that have no meaning here, as paths of the reference."""
    return sorted({raw for raw, documented in _pairs(results) if documented is None})


def documented_paths(results: Mapping[str, Any]) -> set[str]:
    """The documented paths a results.json document holds."""
    return {documented for _, documented in _pairs(results) if documented is not None}


__all__ = [
    "EXPERIMENT_FIELDS",
    "FAILED_ONLY",
    "MARKERLESS_ONLY",
    "RESULTS_FIELDS",
    "documented_paths",
    "undocumented",
]
