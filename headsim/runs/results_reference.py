"""What each key of results.json means: the one source the reference page is made from.

:data:`RESULTS_FIELDS` maps a key's path to its meaning: ``a.b`` a key of a
table, ``a[].b`` a key of each entry of a list, ``a.*`` each key of a table
whose keys are data (a knowledge, a phase).  A path listed without any of its
children is described as a whole (its keys are not listed one by one).
:func:`experiment_fields` gives each procedure's ``experiment`` keys the same
way, relative to ``experiment``, from its declaration (``Procedure.results``).
:func:`undocumented` and :func:`documented_paths` compare a real results.json
with both; the documentation hook (``tools/docs_pages.py``) writes the page
from them.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

from headsim.procedures.contract import procedures
from headsim.runs.outcomes import SURFACE_FIELDS

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
    "settings.head.path": "its MJCF file: `models/NAME.xml` for a shipped head (the same on "
    "every checkout), a user's file by its path",
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

#: ``experiment`` keys a procedure writes only when it failed.
FAILED_ONLY = frozenset({"reason"})

#: ``experiment`` keys written only with markerless targets (``[scene.room] targets``).
MARKERLESS_ONLY = frozenset(SURFACE_FIELDS)


def experiment_fields() -> dict[str, dict[str, str]]:
    """Each procedure's ``experiment`` keys beside ``procedure``, relative to ``experiment``:
    its declaration's ``results``, in the registry's order."""
    return {p.name: dict(p.results) for p in procedures()}


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
    return {f"experiment.{k}": v for k, v in experiment_fields().get(procedure, {}).items()}


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
    "FAILED_ONLY",
    "MARKERLESS_ONLY",
    "RESULTS_FIELDS",
    "documented_paths",
    "experiment_fields",
    "undocumented",
]
