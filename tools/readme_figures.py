"""The figures the README quotes from runs, regenerated from today's code.

Each block of figures in README.md sits between two markers::

    <!-- figures:NAME -->
    ...text written by the generator NAME...
    <!-- /figures:NAME -->

(both indented inside a list item, whose generator indents its text too), and is
written by the generator of that name below (``figures_*.py`` beside this file),
from fresh runs of today's code: scenarios through the runner, studies, the
benchmark scripts' functions.  Every run is seeded, so a block is the same on
every run on one machine.  Usage::

    python tools/readme_figures.py              # check every block; exit 1 naming each stale one
    python tools/readme_figures.py --cheap      # only the blocks that take seconds (a test runs these)
    python tools/readme_figures.py --write      # rewrite the blocks in place
    python tools/readme_figures.py --only NAME  # one block (repeatable)
    python tools/readme_figures.py --jobs 1     # in this process only (default: 2 processes)

Exit codes: 0 every block checked matches, 1 a block differs (its diff is
printed), 2 bad arguments or a marker without its generator (or the reverse).
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

import figures_live as live
import figures_realistic as realistic
import figures_servo as servo
from figures_common import ROOT, bands, calibration_errors, effort, payload, pct, summary

README = ROOT / "README.md"
_BLOCK = re.compile(
    r"(<!-- figures:(?P<name>[\w.-]+) -->\n)(?P<body>.*?)([ \t]*<!-- /figures:(?P=name) -->)", re.S
)


def quickstart() -> str:
    """``headsim run quickstart`` at seed 0: accuracy and what it drew."""
    p = payload("quickstart")
    s, e = summary(p), effort(p)
    return (
        f"`headsim run quickstart` (seed 0): all {s['ok']} of {s['count']} markers measured, "
        f"3-D error RMS **{pct(s['error_pct_of_depth_rms'])} of depth** "
        f"(by depth band: {bands(s)}); {s['renders_per_point']:.1f} renders per marker. "
        f"The run drew {e['renders']} images ({e['calibration_renders']} in the calibration, "
        f"{e['experiment_renders']} in the measurements; {e['windows']} windows and "
        f"{e['previews']} previews among them), {e['frames']:.1f} full frames of pixels.\n"
    )


def realistic_field() -> str:
    """``headsim run realistic_field`` at seed 0: the whole field, effort, the calibration."""
    p = payload("realistic_field")
    s, e = summary(p), effort(p)
    return (
        f"`headsim run realistic_field` (seed 0): {s['ok']} of {s['count']} targets measured "
        f"({s['searched']} needed a search, {s['search_renders']} renders of search); "
        f"3-D error RMS over all {s['count']}: **{pct(s['error_pct_of_depth_rms'])} of depth**; "
        f"by depth band: {bands(s)}; {s['renders_per_point']:.1f} renders per point "
        f"({e['frames']:.0f} full frames of pixels for {e['renders']} "
        f"renders). {_calibration_line(p)}\n"
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


@dataclass(frozen=True)
class Generator:
    """A block's generator: its text from fresh runs.

    ``cheap``: seconds, not minutes (the test suite checks it).  ``group``: blocks that
    share runs (cached per process) are made in one process.  ``seconds``: roughly how
    long the block takes with a core of its own, its own runs only (the longest groups
    start first; the check prints what each group took).
    """

    make: Callable[[], str]
    cheap: bool
    group: str = ""
    seconds: float = 1.0


GENERATORS: dict[str, Generator] = {
    "quickstart": Generator(quickstart, cheap=True, seconds=3),
    "reproduce": Generator(live.reproduce, cheap=False, seconds=45),
    "chessboard_windows": Generator(servo.chessboard_windows, cheap=False, seconds=7),
    "windows": Generator(servo.windows, cheap=False, group="bench points", seconds=5),
    "averaged_fixation": Generator(
        servo.averaged_fixation, cheap=False, group="bench points", seconds=4
    ),
    "reach_zoom": Generator(servo.reach_zoom, cheap=False, group="zoom", seconds=170),
    "reach_zoom_angles": Generator(servo.reach_zoom_angles, cheap=False, group="zoom", seconds=15),
    "relative_areas": Generator(servo.relative_areas, cheap=False, seconds=80),
    "live_gaze": Generator(live.live_gaze, cheap=False, seconds=70),
    "gym": Generator(live.gym_policies, cheap=False, seconds=5),
    "forward_field": Generator(realistic.forward_field, cheap=True, group="forward", seconds=4),
    "forward_budget": Generator(realistic.forward_budget, cheap=True, group="forward", seconds=1),
    "realistic_field": Generator(realistic_field, cheap=False, seconds=8),
    "layouts": Generator(realistic.layouts, cheap=False, group="forward", seconds=35),
    "budget": Generator(realistic.budget, cheap=False, seconds=75),
    "render_fidelity": Generator(servo.render_fidelity, cheap=False, group="fidelity", seconds=30),
    "render_fidelity_presets": Generator(
        servo.render_fidelity_presets, cheap=False, group="fidelity", seconds=20
    ),
}


def blocks(text: str) -> dict[str, str]:
    """Each block's name and body in ``text``."""
    return {m["name"]: m["body"] for m in _BLOCK.finditer(text)}


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
        for part in [pool.submit(_make, group) for group in order]:
            made.update(part.result())
    return {name: made[name] for name in names}


def check(names: Sequence[str], text: str, jobs: int = 1) -> tuple[dict[str, str], list[str]]:
    """The regenerated bodies, and a diff per block that no longer matches."""
    current = blocks(text)
    fresh = generate(names, jobs)
    stale: list[str] = []
    for name in names:
        if fresh[name] != current[name]:
            diff = difflib.unified_diff(
                current[name].splitlines(),
                fresh[name].splitlines(),
                f"README {name}",
                "today",
                lineterm="",
            )
            stale.append("\n".join(diff))
    return fresh, stale


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="rewrite the blocks in place")
    parser.add_argument("--cheap", action="store_true", help="only the blocks that take seconds")
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
    parser.add_argument("--readme", type=Path, default=README, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    text = args.readme.read_text()
    present = blocks(text)
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
    names = args.only or [n for n, g in GENERATORS.items() if g.cheap or not args.cheap]
    fresh, stale = check(names, text, args.jobs)
    if args.write:
        args.readme.write_text(rewrite(text, fresh))
        print(f"readme_figures: wrote {len(fresh)} blocks ({', '.join(fresh)})")
        return 0
    for diff in stale:
        print(diff)
    print(f"readme_figures: {len(names) - len(stale)} of {len(names)} blocks match today's code")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
