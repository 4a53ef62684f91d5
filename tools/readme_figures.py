"""The figures the documentation quotes from runs, regenerated from today's code.

Each block of figures, in README.md or a page under docs/ (most on docs/results.md and
docs/findings.md), sits between two markers::

    <!-- figures:NAME -->
    ...text written by the generator NAME...
    <!-- /figures:NAME -->

(both indented inside a list item, whose generator indents its text too), and is
written by the generator of that name below (``figures_*.py`` beside this file),
from fresh runs of today's code: scenarios through the runner, studies, the
benchmark scripts' functions.  Every run is seeded, so a block is the same on
every run on one machine (but a timed block's numbers, wall-time ratios, which the
check leaves out); a name appears once over all pages. A generator that draws a PNG
for its page (``figures_findings.py``) draws it only with ``--write``.  Usage::

    python tools/readme_figures.py              # check every block; exit 1 naming each stale one
    python tools/readme_figures.py --cheap      # only the blocks that take seconds (a test runs these)
    python tools/readme_figures.py --ci         # all but the few of several minutes (CI runs these)
    python tools/readme_figures.py --write      # rewrite the blocks in place (and the PNGs they show)
    python tools/readme_figures.py --only NAME  # one block (repeatable)
    python tools/readme_figures.py --jobs 1     # in this process only (default: 2 processes)

Exit codes: 0 every block checked matches, 1 a block differs (its diff is
printed), 2 bad arguments, a marker without its generator (or the reverse) or a
name on two pages.
"""

from __future__ import annotations

import argparse
import difflib
import multiprocessing
import os
import re
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import figures_findings as findings
import figures_live as live
import figures_realistic as realistic
import figures_scenes as scenes
import figures_servo as servo
from figures_common import (
    ROOT,
    SEEDS,
    WRITE_ENV,
    acceptance,
    bands,
    calibration_errors,
    effort,
    payload,
    pct,
    seeds_label,
    spread_pct,
    summary,
    table,
)


def pages(root: Path) -> list[Path]:
    """The files that may hold blocks: the README and every page of the site."""
    return [p for p in [root / "README.md", *sorted((root / "docs").rglob("*.md"))] if p.is_file()]


_BLOCK = re.compile(
    r"(<!-- figures:(?P<name>[\w.-]+) -->\n)(?P<body>.*?)([ \t]*<!-- /figures:(?P=name) -->)", re.S
)


def quickstart() -> str:
    """``headsim run quickstart`` at seed 0 (accuracy and what it drew), then over seeds."""
    p = payload("quickstart", seed=0)
    s, e = summary(p), effort(p)
    runs = [summary(payload("quickstart", seed=seed)) for seed in SEEDS]
    per_seed = " / ".join(pct(r["error_pct_of_depth_rms"]) for r in runs)
    return (
        f"`headsim run quickstart` (seed 0): all {s['ok']} of {s['count']} markers measured, "
        f"3-D error RMS **{pct(s['error_pct_of_depth_rms'])} of depth** "
        f"(by depth band: {bands(s)}); {s['renders_per_point']:.1f} renders per marker. "
        f"{_renders_line(e)} Over {seeds_label()} (`--seed N`; each seed draws its own "
        f"calibration balls and random markers): 3-D error RMS median "
        f"**{spread_pct([r['error_pct_of_depth_rms'] for r in runs])} of depth** (min-max "
        f"over the {len(runs)} seeds), {sum(r['ok'] for r in runs)} of "
        f"{sum(r['count'] for r in runs)} markers measured; per seed {per_seed}.\n"
    )


def quickstart_excerpt() -> str:
    """The README's excerpt of what ``headsim run quickstart`` prints (seed 0), cut from
    today's summary: its belief line, the calibration's first rows, the first markers and
    the whole-field line."""
    from headsim.runs.runner import run_scenario
    from headsim.runs.summary import summary_text
    from headsim.scenario.loading import load_scenario

    lines = summary_text(run_scenario(load_scenario("quickstart", seed=0))).splitlines()

    def after(prefix: str, count: int) -> list[str]:
        start = next(i for i, line in enumerate(lines) if line.startswith(prefix))
        return lines[start : start + count]

    field = next(line for line in lines if "3-D error RMS" in line)
    cut = field[: field.index("by depth:") + len("by depth:")] + " ..."
    body = [
        *after("belief:", 1),
        "",
        *after("Calibration of the initial directions", 4),
        "  ...",
        *after("Measurements (", 4),
        "  ...",
        cut,
        "",
        next(line for line in lines if line.startswith(("OK:", "FAILED"))),
    ]
    return "```text\n" + "\n".join(body) + "\n```\n"


def _renders_line(e: dict[str, Any]) -> str:
    """Every image the run drew, by phase and by kind (each one a render)."""
    return (
        f"The run drew {e['renders']} renders: {e['calibration_renders']} in the calibration "
        f"and {e['experiment_renders']} in the experiment ({e['measurement_renders']} of them "
        f"counted by its measurements); by kind {e['images']} full frames, {e['windows']} "
        f"windows, {e['retakes']} windows retaken whole and {e['previews']} previews, "
        f"{e['frames']:.1f} full frames of pixels."
    )


def realistic_field() -> str:
    """``headsim run realistic_field`` at seed 0: the whole field, effort, the calibration."""
    p = payload("realistic_field", seed=0)
    s, e, a = summary(p), effort(p), acceptance(p)
    edge = s["outside_start_view"]
    refused = ", ".join(f"{n} {code}" for code, n in sorted(a["refused"].items())) or "none"
    return (
        f"`headsim run realistic_field` (seed 0): {s['ok']} of {a['accepted']} accepted "
        f"targets measured, {s['ok']} of {a['drawn']} drawn (the reach check refused "
        f"{a['drawn'] - a['accepted']} draws: {refused}); {s['searched']} needed a search, "
        f"{s['search_renders']} renders of search ({s['scan_renders']} of them scanning for "
        f"{s['scanned']} targets the start pose did not show). 3-D error RMS over all "
        f"{s['count']}: **{pct(s['error_pct_of_depth_rms'])} of depth**; by depth band: "
        f"{bands(s)}; over the {edge['count']} targets outside the start pose's view alone: "
        f"{pct(edge['error_pct_of_depth_rms'])}. {s['renders_per_point']:.1f} renders per "
        f"point. {_renders_line(e)} {_calibration_line(p)}\n"
    )


#: The head presets, each with the scenario's own targets and balls (the same seed).
PRESETS = ("ideal", "paper", "realistic")


def _field_run(preset: str, seed: int) -> dict[str, Any]:
    """``realistic_field`` at ``seed`` on ``preset`` (its own preset unchanged, so that the
    run is shared with its block)."""
    if preset == "realistic":
        return payload("realistic_field", seed=seed)
    return payload("realistic_field", seed=seed, **{"head.preset": preset})


def accuracy_by_preset() -> str:
    """``realistic_field`` over seeds on each preset: 3-D error RMS by depth band, the
    median over seeds with its range, and the presets' order seed by seed."""
    runs = {preset: [_field_run(preset, seed) for seed in SEEDS] for preset in PRESETS}
    # A band no target of a seed fell in is left out of that seed's summary.
    first = list(
        dict.fromkeys(b["band"] for p in runs["realistic"] for b in summary(p)["by_depth"])
    )
    rows, overall = [], {}
    for preset, payloads in runs.items():
        sums, accept = [summary(p) for p in payloads], [acceptance(p) for p in payloads]
        cells = []
        for band in first:
            entries = [b for s in sums for b in s["by_depth"] if b["band"] == band]
            cells.append(
                f"{spread_pct([b['error_pct_of_depth_rms'] for b in entries])}; "
                f"{sum(b['count'] for b in entries)}"
            )
        overall[preset] = [s["error_pct_of_depth_rms"] for s in sums]
        rows.append(
            [
                f"`{payloads[0]['scenario']['preset']}`",
                *cells,
                f"{spread_pct(overall[preset])}; {sum(s['count'] for s in sums)}",
                f"{sum(s['ok'] for s in sums)} / {sum(a['drawn'] for a in accept)}",
            ]
        )
    header = ("preset", *first, "all", "measured / drawn")
    text = table(header, rows)
    per_seed = "; ".join(
        f"`{preset}` " + " / ".join(pct(v) for v in values) for preset, values in overall.items()
    )
    orders = []
    for index, a in enumerate(PRESETS):
        for b in PRESETS[index + 1 :]:
            below = sum(
                x is not None and y is not None and x < y
                for x, y in zip(overall[a], overall[b], strict=True)
            )
            orders.append(f"`{a}` < `{b}` in {below} of {len(SEEDS)}")
    return (
        f"Median over {seeds_label()} of each seed's RMS (min-max over the seeds); targets "
        f"over all seeds:\n\n{text}\nThe whole field's RMS seed by seed ({seeds_label()}): "
        f"{per_seed}. Seeds where one preset's RMS is below another's: {'; '.join(orders)}.\n"
    )


def _calibration_line(p: dict[str, Any]) -> str:
    """What the calibration found against the truth, beside its stated standard errors."""
    if p["calibration"] is None:
        return ""
    c = calibration_errors(p)
    line = f"The calibration fixated {c['fixated']} of {c['targets']} ball positions"
    if "baseline_mm" not in c:
        return line + "."

    def pair(key: str) -> str:
        return " / ".join(f"{abs(v):.2f}" for v in c[key])

    return (
        f"{line}, and found the effective baseline {c['baseline_mm']:+.3f} mm off (stated std "
        f"{c['baseline_std_mm']:.3f} mm), the line-of-sight offsets {pair('offsets_mm')} mm off "
        f"(stated std {pair('offsets_std_mm')} mm) and the initial directions "
        f"{pair('directions_mrad')} mrad off (stated std {pair('directions_std_mrad')} mrad)."
    )


#: The stress scenarios whose random targets reach the field's edge, and their seeds.
STRESS_SCENARIOS, STRESS_SEEDS = ("stress_zoom", "stress_shared_field"), range(5)


def _pooled_rms(parts: list[tuple[int, float | None]]) -> float | None:
    """The RMS over the union of groups given as (count, RMS)."""
    n = sum(k for k, r in parts if r is not None)
    if not n:
        return None
    return float((sum(k * r * r for k, r in parts if r is not None) / n) ** 0.5)


def stress() -> str:
    """Every drawn target of the stress scenarios attempted, at seeds 0-4, full size."""
    rows = []
    for name in STRESS_SCENARIOS:
        runs = [payload(name, seed=seed) for seed in STRESS_SEEDS]
        sums = [summary(p) for p in runs]
        accept = [acceptance(p) for p in runs]
        refused: dict[str, int] = {}
        causes: dict[str, int] = {}
        for a, s in zip(accept, sums, strict=True):
            for code, n in a["refused"].items():
                refused[code] = refused.get(code, 0) + n
            for cause, n in s["failure_causes"].items():
                causes[cause] = causes.get(cause, 0) + n
        edge = [s["outside_start_view"] for s in sums]
        scanned = sum(s["scanned"] for s in sums)
        rows.append(
            [
                f"`{name}`",
                f"{sum(s['ok'] for s in sums)} / {sum(a['accepted'] for a in accept)} / "
                f"{sum(a['drawn'] + a['listed'] for a in accept)}",
                ", ".join(f"{n} {c}" for c, n in sorted(refused.items())) or "none",
                ", ".join(f"{n} {c}" for c, n in sorted(causes.items())) or "none",
                pct(_pooled_rms([(s["ok"], s["error_pct_of_depth_rms"]) for s in sums])),
                f"{pct(_pooled_rms([(e['ok'], e['error_pct_of_depth_rms']) for e in edge]))} "
                f"({sum(e['count'] for e in edge)})",
                f"{scanned}, {sum(s['scan_renders'] for s in sums) / scanned:.2f}"
                if scanned
                else "0, -",
            ]
        )
    return table(
        [
            "scenario, seeds 0-4",
            "measured / accepted / drawn",
            "draws refused",
            "failures",
            "3-D RMS, all measured",
            "3-D RMS, outside the start view (targets)",
            "scanned targets, renders of scan each",
        ],
        rows,
    )


@dataclass(frozen=True)
class Generator:
    """A block's generator: its text from fresh runs.

    ``cheap``: seconds, not minutes (the test suite checks it).  ``timed``: its numbers are
    wall-time ratios, which vary from run to run: the check compares its words, ``--write``
    rewrites its numbers.  ``ci``: CI checks it
    (every block but those of several minutes; ``make figures`` checks them all).  ``group``: blocks that
    share runs (cached per process) are made in one process.  ``seconds``: roughly how
    long the block takes with a core of its own, its own runs only (the longest groups
    start first; the check prints what each group took).
    """

    make: Callable[[], str]
    cheap: bool
    timed: bool = False
    ci: bool = True
    group: str = ""
    seconds: float = 1.0


GENERATORS: dict[str, Generator] = {
    "quickstart": Generator(quickstart, cheap=True, seconds=15),
    "quickstart_excerpt": Generator(quickstart_excerpt, cheap=True, seconds=3),
    "reproduce": Generator(live.reproduce, cheap=False, seconds=45),
    "speed": Generator(live.speed, cheap=False, timed=True, seconds=15),
    "chessboard_windows": Generator(servo.chessboard_windows, cheap=False, seconds=7),
    "windows": Generator(servo.windows, cheap=False, group="bench points", seconds=5),
    "averaged_fixation": Generator(
        servo.averaged_fixation, cheap=False, group="bench points", seconds=4
    ),
    "reach_zoom": Generator(servo.reach_zoom, cheap=False, ci=False, group="zoom", seconds=170),
    "reach_zoom_angles": Generator(
        servo.reach_zoom_angles, cheap=False, ci=False, group="zoom", seconds=15
    ),
    "relative_areas": Generator(servo.relative_areas, cheap=False, ci=False, seconds=80),
    "live_gaze": Generator(live.live_gaze, cheap=False, ci=False, seconds=70),
    "gym": Generator(live.gym_policies, cheap=False, seconds=5),
    "pursuit_belief": Generator(live.pursuit_belief, cheap=False, seconds=12),
    "forward_field": Generator(realistic.forward_field, cheap=True, group="forward", seconds=4),
    "forward_budget": Generator(realistic.forward_budget, cheap=True, group="forward", seconds=1),
    "realistic_field": Generator(realistic_field, cheap=False, group="realistic field", seconds=8),
    "accuracy_by_preset": Generator(
        accuracy_by_preset, cheap=False, ci=False, group="realistic field", seconds=150
    ),
    "stress": Generator(stress, cheap=False, ci=False, seconds=100),
    "layouts": Generator(realistic.layouts, cheap=False, group="forward", seconds=35),
    "budget": Generator(realistic.budget, cheap=False, ci=False, seconds=75),
    "heads": Generator(servo.heads, cheap=False, ci=False, seconds=500),
    "render_fidelity": Generator(servo.render_fidelity, cheap=False, group="fidelity", seconds=30),
    "render_fidelity_presets": Generator(
        servo.render_fidelity_presets, cheap=False, group="fidelity", seconds=20
    ),
    "batch_centroids": Generator(servo.batch_centroids, cheap=False, seconds=60),
    # docs/results.md's real scenes: the room's runs over the seeds.
    "natural_field": Generator(
        scenes.natural_field, cheap=False, ci=False, group="scenes", seconds=120
    ),
    "room_procedures": Generator(
        scenes.room_procedures, cheap=False, ci=False, group="scenes", seconds=200
    ),
    "failure_modes": Generator(
        scenes.failure_modes, cheap=False, ci=False, group="scenes", seconds=100
    ),
    # docs/findings.md: the Tables V/VI experiment at full size over the seeds, shared.
    "findings_figure": Generator(
        findings.findings_figure, cheap=False, ci=False, group="findings", seconds=300
    ),
    "findings_xz": Generator(findings.findings_xz, cheap=False, ci=False, group="findings"),
    "findings_y": Generator(findings.findings_y, cheap=False, ci=False, group="findings"),
    "findings_zoom": Generator(findings.findings_zoom, cheap=False, ci=False, group="findings"),
}


def blocks(text: str) -> dict[str, str]:
    """Each block's name and body in ``text``."""
    return {m["name"]: m["body"] for m in _BLOCK.finditer(text)}


def located(root: Path) -> tuple[dict[str, tuple[Path, str]], list[str]]:
    """Each block's page and body under ``root``, and the names found on two pages."""
    found: dict[str, tuple[Path, str]] = {}
    twice: list[str] = []
    for page in pages(root):
        for name, body in blocks(page.read_text()).items():
            if name in found:
                twice.append(name)
            found[name] = (page, body)
    return found, twice


def rewrite(text: str, bodies: dict[str, str]) -> str:
    """``text`` with the named blocks' bodies replaced."""

    def one(m: re.Match[str]) -> str:
        body = bodies.get(m["name"], m["body"])
        return f"{m.group(1)}{body}{m.group(4)}"

    return _BLOCK.sub(one, text)


def _make(names: Sequence[str]) -> dict[str, str]:
    """The named blocks' text, made in this process, each group's wall time on stderr."""
    start = time.perf_counter()
    out = {name: GENERATORS[name].make() for name in names}
    print(
        f"readme_figures: {', '.join(names)}: {time.perf_counter() - start:.0f} s",
        file=sys.stderr,
        flush=True,
    )
    return out


def generate(names: Sequence[str], jobs: int = 1) -> dict[str, str]:
    """Each named block's fresh text; the groups in ``jobs`` processes, the longest first."""
    groups: dict[str, list[str]] = {}
    for name in names:
        groups.setdefault(GENERATORS[name].group or name, []).append(name)
    if jobs <= 1 or len(groups) <= 1:
        return _make(names)
    order = sorted(groups.values(), key=lambda g: -sum(GENERATORS[n].seconds for n in g))
    spawn = multiprocessing.get_context("spawn")  # EGL does not survive a fork
    made: dict[str, str] = {}
    with ProcessPoolExecutor(max_workers=jobs, mp_context=spawn) as pool:
        parts = {pool.submit(_make, group): group for group in order}
        for part, group in parts.items():
            try:
                made.update(part.result())
            except Exception as err:  # one broken generator must not lose the others' work
                print(f"readme_figures: {', '.join(group)} failed: {err!r}", file=sys.stderr)
    return {name: made[name] for name in names if name in made}


_NUMBER = re.compile(r"\d+(\.\d+)?")


def _compared(name: str, body: str) -> str:
    """What the check compares of a block: its text, a timed block's without its numbers."""
    return _NUMBER.sub("#", body) if GENERATORS[name].timed else body


def check(
    names: Sequence[str], current: dict[str, tuple[Path, str]], root: Path, jobs: int = 1
) -> tuple[dict[str, str], list[str]]:
    """The regenerated bodies, and a diff per block that no longer matches."""
    fresh = generate(names, jobs)
    stale: list[str] = []
    for name in names:
        page, body = current[name]
        where = f"{page.relative_to(root)} {name}"
        if name not in fresh:
            stale.append(f"{where}: its generator failed (above)")
        elif _compared(name, fresh[name]) != _compared(name, body):
            diff = difflib.unified_diff(
                body.splitlines(),
                fresh[name].splitlines(),
                where,
                "today",
                lineterm="",
            )
            stale.append("\n".join(diff))
    return fresh, stale


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="rewrite the blocks in place")
    parser.add_argument("--cheap", action="store_true", help="only the blocks that take seconds")
    parser.add_argument("--ci", action="store_true", help="only the blocks CI checks")
    parser.add_argument(
        "--only", action="append", default=[], metavar="NAME", help="one block (repeatable)"
    )
    parser.add_argument(
        "--jobs",
        type=int,
        default=min(2, os.cpu_count() or 1),
        metavar="N",
        help="processes that make the blocks (default: 2, or 1 on one CPU)",
    )
    parser.add_argument("--root", type=Path, default=ROOT, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    present, twice = located(args.root)
    if twice:
        print(f"readme_figures: blocks on two pages: {sorted(twice)}", file=sys.stderr)
        return 2
    unknown = sorted(set(present) - set(GENERATORS))
    missing = sorted(set(GENERATORS) - set(present))
    if unknown or missing:
        print(
            f"readme_figures: blocks without a generator: {unknown or 'none'}; "
            f"generators without a block: {missing or 'none'}",
            file=sys.stderr,
        )
        return 2
    bad = [n for n in args.only if n not in GENERATORS]
    if bad:
        print(
            f"readme_figures: --only {bad[0]!r}: not a block (allowed: {', '.join(GENERATORS)})",
            file=sys.stderr,
        )
        return 2
    names = args.only or [
        n
        for n, g in GENERATORS.items()
        if (g.cheap or not args.cheap) and (g.ci or g.cheap or not args.ci)
    ]
    if args.write:
        os.environ[WRITE_ENV] = "1"  # the generators' processes inherit it
    fresh, stale = check(names, present, args.root, args.jobs)
    if args.write:
        for page in {present[name][0] for name in fresh}:
            page.write_text(rewrite(page.read_text(), fresh))
        print(f"readme_figures: wrote {len(fresh)} blocks ({', '.join(fresh)})")
        return 0 if len(fresh) == len(names) else 1
    for diff in stale:
        print(diff)
    print(f"readme_figures: {len(names) - len(stale)} of {len(names)} blocks match today's code")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
