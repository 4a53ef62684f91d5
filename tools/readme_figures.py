"""The figures the README quotes from runs, regenerated from today's code.

Each block of figures in README.md sits between two markers::

    <!-- figures:NAME -->
    ...text written by the generator NAME...
    <!-- /figures:NAME -->

and is written by the generator of that name below, from fresh runs of the
scenarios it names (the seeds are the scenarios', so a block is the same on
every run on one machine).  Usage::

    python tools/readme_figures.py              # check every block; exit 1 naming each stale one
    python tools/readme_figures.py --cheap      # only the blocks that take seconds (a test runs these)
    python tools/readme_figures.py --write      # rewrite the blocks in place
    python tools/readme_figures.py --only NAME  # one block (repeatable)

Exit codes: 0 every block checked matches, 1 a block differs (its diff is
printed), 2 bad arguments or a marker without its generator (or the reverse).
"""

from __future__ import annotations

import argparse
import difflib
import re
import sys
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
_BLOCK = re.compile(
    r"(<!-- figures:(?P<name>[\w.-]+) -->\n)(?P<body>.*?)(<!-- /figures:(?P=name) -->)", re.S
)


def run_payload(
    scenario: str, *, fast: bool = False, seed: int | None = None, **overrides: Any
) -> dict[str, Any]:
    """results.json's document of one scenario run (no files written)."""
    from headsim.run.runner import run_scenario
    from headsim.run.serialise import results_payload
    from headsim.scenario.loading import load_scenario

    loaded = load_scenario(scenario, fast=fast, seed=seed, overrides=overrides or None)
    return results_payload(run_scenario(loaded))


def pct(value: float | None, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}f} %"


def _summary(payload: dict[str, Any]) -> dict[str, Any]:
    """The run's one summary entry (the knowledge the head measured with)."""
    (entry,) = payload["summary"].values()
    return entry


def _bands(entry: dict[str, Any]) -> str:
    return "; ".join(
        f"{b['band']}: {pct(b['error_pct_of_depth_rms'])} ({b['count']})" for b in entry["by_depth"]
    )


def quickstart() -> str:
    p = run_payload("quickstart")
    s = _summary(p)
    r, w = p["renders"], p["windows"]
    return (
        f"`headsim run quickstart` (seed 0): all {s['ok']} of {s['count']} markers measured, "
        f"3-D error RMS **{pct(s['error_pct_of_depth_rms'])} of depth** "
        f"(by depth band: {_bands(s)}); {s['renders_per_point']:.1f} renders per marker. "
        f"The run drew {r['total']} images ({r['calibration']} in the calibration, "
        f"{r['experiment']} in the measurements; {w['rendered']} windows and {w['previews']} "
        f"previews among them), {p['rendered_frames']['total']:.1f} full frames of pixels.\n"
    )


def realistic_field() -> str:
    p = run_payload("realistic_field")
    s = _summary(p)
    c = p["calibration"]
    return (
        f"`headsim run realistic_field` (seed 0): {s['ok']} of {s['count']} targets measured "
        f"({s['searched']} needed a search, {s['search_renders']} renders of search); "
        f"3-D error RMS over all {s['count']}: **{pct(s['error_pct_of_depth_rms'])} of depth**; "
        f"by depth band: {_bands(s)}; {s['renders_per_point']:.1f} renders per point "
        f"({p['rendered_frames']['total']:.0f} full frames of pixels for {p['renders']['total']} "
        f"renders). {_calibration_line(c)}\n"
    )


def _calibration_line(c: dict[str, Any] | None) -> str:
    """What the calibration found against the truth, beside its stated standard errors."""
    if c is None:
        return ""
    line = f"The calibration fixated {c['fixated']} of {c['targets']} ball positions"
    los = c.get("lines_of_sight")
    if not los:
        return line + "."
    baseline_mm = 1000 * (los["effective_baseline_m"] - los["effective_baseline_truth_m"])
    offsets_mm = [
        1000 * abs(a - b) for a, b in zip(los["offset_m"], los["offset_truth_m"], strict=True)
    ]
    directions_mrad = [
        1000 * abs(a - b) for a, b in zip(los["alpha_e_rad"], c["alpha_e_truth_rad"], strict=True)
    ]
    std = los["std_errors"]
    return (
        f"{line}, and found the effective baseline {baseline_mm:+.3f} mm off (stated std "
        f"{1000 * los['effective_baseline_std_m']:.3f} mm), the line-of-sight offsets "
        f"{offsets_mm[0]:.2f} / {offsets_mm[1]:.2f} mm off (stated std "
        f"{1000 * std['offset_m'][0]:.2f} / {1000 * std['offset_m'][1]:.2f} mm) and the initial "
        f"directions {directions_mrad[0]:.2f} / {directions_mrad[1]:.2f} mrad off (stated std "
        f"{1000 * std['alpha_e_rad'][0]:.2f} / {1000 * std['alpha_e_rad'][1]:.2f} mrad)."
    )


@dataclass(frozen=True)
class Generator:
    make: Callable[[], str]
    cheap: bool  # seconds, not minutes: the test suite checks it


GENERATORS: dict[str, Generator] = {
    "quickstart": Generator(quickstart, cheap=True),
    "realistic_field": Generator(realistic_field, cheap=False),
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


def check(names: Iterable[str], text: str) -> tuple[dict[str, str], list[str]]:
    """The regenerated bodies, and a diff per block that no longer matches."""
    current = blocks(text)
    fresh: dict[str, str] = {}
    stale: list[str] = []
    for name in names:
        fresh[name] = GENERATORS[name].make()
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
    fresh, stale = check(names, text)
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
