"""The summary table of a run, for people: the calibration, the measurements, the experiment.

It reads the typed results (:mod:`headsim.runs.outcomes`); results.json is
written by :mod:`headsim.runs.serialise`.  The figures of the paper are shown
beside ours for its head; lengths in mm, errors in % of depth.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from headsim.active.calibration_report import CalibrationReport
from headsim.procedures.contract import get
from headsim.runs.accuracy import DepthBand, summaries
from headsim.runs.outcomes import RunOutcome, SurfaceBlock, TextureClassStats, fixation_stats
from headsim.runs.table import cell as _cell
from headsim.runs.table import format_table
from headsim.runs.table import mm as _mm
from headsim.scenario.spec import Scenario, TargetAcceptance
from headsim.sim.events import RenderCounts

# -- the summary table ------------------------------------------------------------


def _calibration_lines(report: CalibrationReport, paper: bool) -> list[str]:
    lines = [
        f"Calibration of the initial directions (Sec. V): {report.fixated} of "
        f"{report.targets} ball positions fixated, {report.renders.total} renders"
    ]
    missed = [p.status for p in report.positions if p.failure is not None]
    if missed:
        counts: dict[str, int] = {}
        for status in missed:
            key = status.split(" (")[0]
            counts[key] = counts.get(key, 0) + 1
        lines.append("  not fixated: " + ", ".join(f"{n} {k}" for k, n in counts.items()))
    if not report.ok:
        return [*lines, f"  {report.status_text}"]
    alpha_e = report.alpha_e_rad
    std = report.alpha_e_std_rad
    truth_e = report.alpha_e_truth_rad
    error = report.alpha_e_error_rad
    paper_e = report.alpha_e_paper_rad
    assert alpha_e is not None and std is not None and truth_e is not None
    assert error is not None and paper_e is not None
    headers = ["", "ours", "+-", "truth", "error"] + (["paper"] if paper else [])
    rows = []
    for k in range(2):
        rows.append(
            [
                f"alpha_e{k + 1} (rad)",
                _cell(alpha_e[k], ".5f"),
                _cell(std[k], ".1e"),
                _cell(truth_e[k], ".5f"),
                _cell(error[k], "+.1e"),
                *([_cell(paper_e[k], ".4f")] if paper else []),
            ]
        )

    def extended(label: str, fmts: str, *columns: Sequence[float], scale: float = 1.0) -> None:
        """A row per camera (``{k}`` in ``label``: its number) of ``columns`` ours, its standard
        error and the truth, then ours minus the truth, each times ``scale``, as ``fmts``."""
        for k, (ours, std, truth) in enumerate(zip(*columns, strict=True), start=1):
            cells = (scale * ours, scale * std, scale * truth, scale * (ours - truth))
            texts = [_cell(c, f) for c, f in zip(cells, fmts.split(), strict=True)]
            rows.append([label.format(k=k), *texts, *(["-"] if paper else [])])

    vertical, los = report.vertical_reference, report.lines_of_sight
    if vertical:
        v = vertical
        extended("v{k}0 (px, extended)", ".2f .2f .2f +.2f", v.v0_px, v.v0_std_px, v.v0_truth_px)
        ratios = (v.kx_over_ky, v.kx_over_ky_std, v.kx_over_ky_truth)
        extended("kx{k}/ky{k} (extended)", ".4f .4f .4f +.4f", *ratios)
    if los:
        angles = (los.alpha_e_rad, los.std_errors_alpha_e_rad, truth_e)
        extended("alpha_e{k} (rad, extended)", ".5f .1e .5f +.1e", *angles)
        offsets = (los.offset_m, los.std_errors_offset_m, los.offset_truth_m)
        extended("s{k} (mm, extended)", ".3f .3f .3f +.3f", *offsets, scale=1e3)
        baseline = (
            los.effective_baseline_m,
            los.effective_baseline_std_m,
            los.effective_baseline_truth_m,
        )
        extended("D effective (mm)", ".3f .3f .3f +.3f", *([b] for b in baseline), scale=1e3)
    out = lines + format_table(headers, rows)
    if los and not los.separable:
        out.append(f"  line-of-sight offsets: {los.message}")
    return out


def _measurement_lines(result: RunOutcome) -> list[str]:
    records = result.records
    if not records:
        return []
    tracking = any(r.time_s is not None for r in records)
    several = len({r.knowledge for r in records}) > 1
    headers = ["name", *(["t s"] if tracking else []), *(["head knew"] if several else [])]
    pairs = any(len(r.measurement.servo_residual_px) == 2 for r in records)
    residual_header = "residual px (Ca1 Ca2)" if pairs else "residual px"
    headers += ["status", "depth m", "error mm", "% depth", "renders", residual_header]
    rows = []
    for r in records:
        m = r.measurement
        error = float(np.linalg.norm(m.error_head_m))
        residual = " ".join(_cell(x, ".2f") for x in m.servo_residual_px) or "-"
        rows.append(
            [
                m.name,
                *([_cell(r.time_s, ".2f")] if tracking else []),
                *([r.knowledge] if several else []),
                m.status_text,
                _cell(m.depth_m, ".3f"),
                _mm(error),
                _cell(m.error_pct_of_depth, ".3f"),
                str(m.renders),
                residual,
            ]
        )
    methods = ", ".join(sorted({r.measurement.method.value for r in records}))
    lines = [f"Measurements ({methods}; error = |estimate - truth| in H)"]
    lines += format_table(headers, rows)
    acceptance = result.scenario.scene.acceptance
    edge = () if acceptance is None else acceptance.outside_start_view
    markerless = any(r.fixation is not None for r in records)
    surface = getattr(result.experiment, "surface_targets", None)
    if isinstance(surface, SurfaceBlock) and surface.listed == surface.asked:
        markerless = False  # listed points only: not the whole field
    for label, s in summaries(records, edge).items():
        lines.append(
            f"  head knew {label}: {s.ok} of {s.count} ok; error mean {_mm(s.error_m_mean)} mm "
            f"({_cell(s.error_pct_of_depth_mean, '.3f')} % of depth), max {_mm(s.error_m_max)} mm; "
            f"{_cell(s.renders_per_point, '.1f')} renders per point; servo residual "
            f"<= {_cell(s.servo_residual_px_max, '.2f')} px"
        )
        if acceptance is not None and acceptance.drawn and s.count == acceptance.accepted:
            lines.append(f"    {_acceptance_text(s.ok, acceptance)}")
        if s.searched:
            scanned = (
                f" ({s.scanned} scanned for where the head's pose did not show them: "
                f"{s.scan_renders} renders, {s.scan_renders / s.scanned:.1f} per target)"
                if s.scanned
                else ""
            )
            lines.append(
                f"    {s.searched} targets searched for again, "
                f"{s.search_renders} renders of search{scanned}"
            )
        if s.failure_causes:
            causes = ", ".join(f"{n} {c}" for c, n in s.failure_causes.items())
            lines.append(f"    failures by cause: {causes}")
        bands = "; ".join(band_text(b) for b in s.by_depth)
        lines.append(
            f"    {_targets_text(s.ok, s.count, acceptance, markerless)}: 3-D error RMS "
            f"{_cell(s.error_pct_of_depth_rms, '.3f')} % of depth; by depth: {bands}"
        )
        g = s.outside_start_view
        if g.count:
            lines.append(
                f"    of them at the edge of the field (not seen whole by both cameras at the "
                f"start pose): {g.ok} of {g.count} measured, 3-D error RMS "
                f"{_cell(g.error_pct_of_depth_rms, '.3f')} % of depth"
            )
    return lines + _markerless_lines(result)


def _markerless_lines(result: RunOutcome) -> list[str]:
    """Markerless targets: how they were drawn, and where the eyes truly landed."""
    stats = fixation_stats(result.records)
    if not stats.count:
        return []
    lines = []
    surface = getattr(result.experiment, "surface_targets", None)
    if isinstance(surface, SurfaceBlock):
        refused = ", ".join(f"{n} {c}" for c, n in surface.refused.items()) or "none"
        listed = f"{surface.listed} listed, " if surface.listed else ""
        what = "markerless targets" if surface.measured_as == "surface" else "points"
        lines.append(
            f"  {what}: {surface.asked} asked on the room's surfaces ({listed}"
            f"{surface.drawn} draws, refused and drawn again: {refused})"
        )
    ok = sum(1 for r in result.records if r.fixation is not None and r.measurement.ok)
    causes = ", ".join(f"{n} {c}" for c, n in stats.failure_causes.items()) or "none"
    twin = isinstance(surface, SurfaceBlock) and surface.measured_as == "markers"
    if twin:
        lines.append(
            "  each measured with a marker put there (5 mm out along the normal), not by "
            "correlation; scored against the marker's centre: each eye's fixated point is "
            "its ray's point nearest the centre (the ray meets the sphere's front)"
        )
    lines.append(
        f"  {'marker' if twin else 'markerless'} fixations (truth: where each eye's goal ray "
        f"landed): vergence error "
        f"median {_cell(stats.vergence_error_deg_median, '.4f')} deg, RMS "
        f"{_cell(stats.vergence_error_deg_rms, '.4f')} deg; false fixations "
        f"{stats.false_fixations} of {ok} ok (an eye landed > max(1 % of depth, 5 mm) off); "
        f"confident matches on a wrong point {stats.wrong_matches} "
        f"({stats.wrong_matches_failed} of them in failed measurements); "
        f"failures by cause: {causes}"
    )
    if isinstance(surface, SurfaceBlock) and surface.by_texture:
        lines.append(
            "  by texture class (truth at placement; occluded: part of a template hidden):"
        )
        lines += [f"    {texture_text(c)}" for c in surface.by_texture]
    return lines


def texture_text(c: TextureClassStats) -> str:
    """One texture class's line, with the same figures as the whole: measured of asked,
    3-D RMS, vergence error, false fixations, failures by cause, renders per point."""
    if not c.asked:
        return f"{c.texture_class}: no targets"
    causes = ", ".join(f"{n} {k}" for k, n in c.failure_causes.items()) or "none"
    if not c.measured:
        return (
            f"{c.texture_class}: 0 of {c.asked} measured; failures by cause: {causes}; "
            f"{_cell(c.renders_per_point, '.1f')} renders per point"
        )
    return (
        f"{c.texture_class}: {c.measured} of {c.asked} measured, 3-D RMS "
        f"{_cell(c.error_pct_of_depth_rms, '.3f')} % of depth; vergence error median "
        f"{_cell(c.vergence_error_deg_median, '.4f')} deg, RMS "
        f"{_cell(c.vergence_error_deg_rms, '.4f')} deg; false fixations {c.false_fixations}; "
        f"failures by cause: {causes}; {_cell(c.renders_per_point, '.1f')} renders per point"
    )


def _targets_text(ok: int, count: int, a: TargetAcceptance | None, markerless: bool = False) -> str:
    """Which targets the RMS is over: "the whole field" only for targets drawn over it."""
    measured = f"all {ok} targets measured" if ok == count else f"the {ok} of {count} measured"
    if markerless:
        return f"whole field, {measured} (points of the room's surfaces drawn over it)"
    if a is None or not a.drawn:
        return f"{measured} (placed by hand)"
    drawn = a.accepted - a.listed
    if not a.listed:
        return f"whole field, {measured} (drawn over it)"
    return f"{measured} ({a.listed} placed by hand, {drawn} drawn over the field)"


def _acceptance_text(ok: int, a: TargetAcceptance) -> str:
    """ "measured / accepted" beside "measured / drawn", with what the reach check refused."""
    offered = "drawn" if not a.listed else "listed or drawn"
    refused = ", ".join(f"{n} {code}" for code, n in a.refused.items())
    return f"{ok} of {a.accepted} accepted targets measured, {ok} of {a.offered} {offered}" + (
        f" ({a.refused_total} draws refused by the reach check and drawn again: {refused})"
        if a.refused
        else " (the reach check refused none)"
    )


def _renders_text(counts: RenderCounts) -> str:
    """ "107 renders (40 full frames, 44 windows, 1 retake, 22 previews)"."""

    def n(count: int, what: str) -> str:
        return f"{count} {what}{'' if count == 1 else 's'}"

    return (
        f"{n(counts.total, 'render')} ({n(counts.images, 'full frame')}, "
        f"{n(counts.windows, 'window')}, {n(counts.retakes, 'retake')}, "
        f"{n(counts.previews, 'preview')})"
    )


def _head_text(scenario: Scenario) -> str:
    """Which head ran, where it is not the paper's (the line's start)."""
    head = scenario.settings.head
    return "" if head.is_paper else f"{head.name} ({head.mapping.eyes} eyes), "


#: How the summary names where a believed quantity came from (``belief.sources``).
_SOURCE_TEXT = {
    "design": "from the design",
    "preset": "the preset's belief",
    "file": "from [belief]",
    "given": "given",
    "truth": "equal to the truth (set in [head], no [belief])",
}


def belief_text(scenario: Scenario) -> str:
    """ "belief: baseline 150 mm, neck d1 120 mm, a2 90 mm: from the design; ..." -- what the
    estimators used and where each came from (the forward offsets, which none uses, left out)."""
    b = scenario.settings.believed
    values = {
        "baseline_m": f"baseline {1e3 * b.baseline_m:g} mm",
        "neck_d1_m": f"neck d1 {1e3 * b.neck_d1_m:g} mm",
        "neck_a2_m": f"neck a2 {1e3 * b.neck_a2_m:g} mm",
        "side_offset_m": "side offsets "
        + "/".join(f"{1e3 * v:g}" for v in b.side_offset_m)
        + " mm",
    }
    groups: dict[str, list[str]] = {}
    for key, source in scenario.believed_from.items():
        if key in values:
            groups.setdefault(source, []).append(values[key])
    return "belief: " + "; ".join(
        f"{', '.join(parts)}: {_SOURCE_TEXT.get(source, source)}"
        for source, parts in groups.items()
    )


def band_figure(b: DepthBand) -> str:
    """One depth band's figure: its RMS over the targets measured in it, how many of
    those asked there were measured (when not all), or that it held no target."""
    if not b.asked:
        return "no targets"
    if not b.count:
        return f"0 of {b.asked} measured"
    of = f" of {b.asked} measured" if b.count < b.asked else ""
    return f"{_cell(b.error_pct_of_depth_rms, '.3f')} % ({b.count}{of})"


def band_text(b: DepthBand) -> str:
    """The band's name and :func:`band_figure`."""
    return f"{b.band}: {band_figure(b)}"


def summary_text(result: RunOutcome, head_flag: str | None = None) -> str:
    """The table printed at the end of a run (figures of the paper beside ours for its
    head).  ``head_flag``: the head ``--head`` put in place of the file's (the file's
    description, written for its own head, is then left out)."""
    s = result.scenario
    paper = s.paper_cameras
    e = result.experiment
    variant = " (fast variant)" if s.fast else ""
    lines = [
        f"{s.name}{variant}: {s.description}"
        if head_flag is None
        else f"{s.name}{variant} with --head {head_flag} (the file describes its own head)",
        f"head: {_head_text(s)}{s.preset} preset; seed {s.seed}; procedure {s.experiment.procedure}; "
        f"{_renders_text(result.renders.overall)}"
        + (
            f"; {result.rendered_frames['total']:.1f} full frames of pixels"
            if result.rendered_frames
            else ""
        )
        + ("; the paper's figures beside ours" if paper else ""),
        belief_text(s),
        "",
    ]
    if result.calibration is not None:
        lines += [*_calibration_lines(result.calibration, paper), ""]
    measurement = _measurement_lines(result)
    if measurement:
        lines += [*measurement, ""]
    procedure = get(s.experiment.procedure)
    if e is not None:
        own = procedure.summary(e, paper)
        if own:
            lines += [*own, ""]
    if result.ok:
        lines.append(procedure.ok_line(e, len(result.records)))
    else:
        lines.append(f"FAILED: {len(result.failures)} problem(s)")
        lines += [f"  {f}" for f in result.failures]
    return "\n".join(lines)


__all__ = ["belief_text", "format_table", "summary_text", "texture_text"]
