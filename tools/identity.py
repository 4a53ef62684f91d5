"""Byte-identity check for refactors: every scenario's results.json, fast and full.

A change that should alter no behaviour (a restructuring) must leave every
scenario's results.json byte-identical, and the bench's accuracy metrics equal.

    python tools/identity.py collect OUT_DIR [--jobs N] [--only NAME ...]
    python tools/identity.py compare BEFORE_DIR AFTER_DIR
    python tools/identity.py fuzz OUT.json [--cases N]

`fuzz` runs the scenario fuzzer's mutations (tests/scenario/test_fuzz_scenarios.py,
same seed) and writes each case's outcome: accepted, or the refusal's message.
`compare` lists the cases whose outcome changed when both folders hold a fuzz.json.

`collect` runs `headsim run NAME --out ...` for every scenario shipped in
headsim's scenarios folder, with and without --fast, plus `headsim bench --json`
and `headsim reproduce --fast`, and keeps the JSON outputs. `compare` prints a
sha256 per file, the differing files, and the bench metrics that differ apart
from the speed ones (timings are not deterministic). Exit status 1 on a
difference.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "scenarios"
HEADSIM = [sys.executable, "-m", "headsim.cli"]
# Keys of `reproduce`'s report that carry clock readings, worker ids or CPU ratios
# (seconds end in _s); render counts and every result stay in the comparison.
_TIMING_KEYS = ("wall", "cpu", "render_time", "timeline", "pid", "start", "end", "shutdown")


def _run(args: list[str], out: Path) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
    proc = subprocess.run(args, cwd=ROOT, env=env, capture_output=True, text=True)
    (out.parent / (out.name + ".log")).write_text(proc.stdout + proc.stderr)
    if proc.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(args)}: exit {proc.returncode}\n{proc.stderr[-2000:]}")


def _scenario_job(name: str, fast: bool, dest: Path) -> str:
    tag = f"{name}{'-fast' if fast else ''}"
    with tempfile.TemporaryDirectory() as tmp:
        args = [*HEADSIM, "--quiet", "run", name, "--out", tmp]
        if fast:
            args.append("--fast")
        _run(args, dest / tag)
        shutil.copy(Path(tmp) / "results.json", dest / f"{tag}.results.json")
    return tag


def collect(dest: Path, jobs: int, only: list[str]) -> None:
    dest.mkdir(parents=True, exist_ok=True)
    names = sorted(p.stem for p in SCENARIOS.glob("*.toml"))
    if only:
        names = [n for n in names if n in only]
    work = [(n, f) for n in names for f in (True, False)]
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        for tag in pool.map(lambda nf: _scenario_job(nf[0], nf[1], dest), work):
            print("ran", tag, flush=True)
    if not only:
        _run([*HEADSIM, "--quiet", "bench", "--json", str(dest / "bench.json")], dest / "bench")
        print("ran bench", flush=True)
        with tempfile.TemporaryDirectory() as tmp:
            _run(
                [*HEADSIM, "--quiet", "reproduce", "--fast", "--workers", "2", "--out", tmp],
                dest / "reproduce",
            )
            shutil.copy(Path(tmp) / "report.json", dest / "reproduce.report.json")
        print("ran reproduce --fast", flush=True)


def fuzz(dest: Path, cases: int) -> None:
    """Each mutated scenario's outcome, in the fuzzer's order: "accepted" or the error text."""
    import importlib.util
    import random

    from headsim.scenario.loading import load_scenario
    from headsim.scenario.tables import ScenarioError

    spec = importlib.util.spec_from_file_location(
        "fuzz_cases", ROOT / "tests" / "scenario" / "test_fuzz_scenarios.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rng = random.Random(module.SEED)
    names = sorted(module.BASES)
    outcomes: list[dict[str, str]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in range(cases):
            base = names[case % len(names)]
            kind, text = module.mutate(module.BASES[base], rng)
            if rng.random() < 0.3:
                kind2, text = module.mutate(text, rng)
                kind = f"{kind}+{kind2}"
            path = Path(tmp) / f"case{case}.toml"
            path.write_text(text, encoding="utf-8", errors="surrogatepass")
            try:
                load_scenario(path)
                outcome = "accepted"
            except ScenarioError as err:
                outcome = f"refused: {err}"
            except Exception as err:  # a traceback the fuzzer test would fail on
                outcome = f"TRACEBACK {type(err).__name__}: {err}"
            outcome = outcome.replace(tmp, "TMP")  # the temporary folder differs per run
            outcomes.append({"case": str(case), "base": base, "kind": kind, "outcome": outcome})
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.write_text(json.dumps(outcomes, indent=1))
    tracebacks = sum(o["outcome"].startswith("TRACEBACK") for o in outcomes)
    refused = sum(o["outcome"].startswith("refused") for o in outcomes)
    print(f"fuzz: {cases} cases, {refused} refused, {tracebacks} tracebacks -> {dest}")


def _compare_fuzz(pa: Path, pb: Path) -> int:
    a_cases, b_cases = json.loads(pa.read_text()), json.loads(pb.read_text())
    changed = [(a, b) for a, b in zip(a_cases, b_cases, strict=False) if a != b]
    for a, b in changed:
        print(f"  case {a['case']} ({a['base']}, {a['kind']}):")
        print(f"    before: {a['outcome'][:300]}")
        print(f"    after:  {b['outcome'][:300]}")
    same = not changed and len(a_cases) == len(b_cases)
    print(f"{'same' if same else 'DIFF'}  fuzz.json ({len(changed)} outcome(s) changed)")
    return 0 if same else 1


def _strip_timing(value: object) -> object:
    if isinstance(value, dict):
        return {
            k: _strip_timing(v)
            for k, v in value.items()
            if not any(t in k.lower() for t in _TIMING_KEYS)
        }
    if isinstance(value, list):
        return [_strip_timing(v) for v in value]
    return value


def compare(before: Path, after: Path) -> int:
    bad = 0
    for path in sorted(before.glob("*.results.json")):
        other = after / path.name
        a = hashlib.sha256(path.read_bytes()).hexdigest()
        b = hashlib.sha256(other.read_bytes()).hexdigest() if other.exists() else "missing"
        same = a == b
        bad += not same
        print(f"{'same' if same else 'DIFF'}  {a[:16]}  {b[:16]}  {path.name}")
    for name in ("bench.json", "reproduce.report.json"):
        pa, pb = before / name, after / name
        if not pa.exists():
            continue
        if not pb.exists():
            print(f"DIFF  {name} missing after")
            bad += 1
            continue
        a_doc, b_doc = json.loads(pa.read_text()), json.loads(pb.read_text())
        if name == "bench.json":
            a_doc = {
                k: v
                for k, v in a_doc.get("metrics", a_doc).items()
                if "speed" not in k and "ratio" not in k
            }
            b_doc = {
                k: v
                for k, v in b_doc.get("metrics", b_doc).items()
                if "speed" not in k and "ratio" not in k
            }
        same = _strip_timing(a_doc) == _strip_timing(b_doc)
        bad += not same
        print(f"{'same' if same else 'DIFF'}  {name} (timings left out)")
    if (before / "fuzz.json").exists() and (after / "fuzz.json").exists():
        bad += _compare_fuzz(before / "fuzz.json", after / "fuzz.json")
    print(f"{bad} difference(s)")
    return 1 if bad else 0


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = parser.add_subparsers(dest="verb", required=True)
    c = sub.add_parser("collect")
    c.add_argument("dest", type=Path)
    c.add_argument("--jobs", type=int, default=2)
    c.add_argument("--only", nargs="*", default=[])
    d = sub.add_parser("compare")
    d.add_argument("before", type=Path)
    d.add_argument("after", type=Path)
    f = sub.add_parser("fuzz")
    f.add_argument("dest", type=Path)
    f.add_argument("--cases", type=int, default=2000)
    args = parser.parse_args()
    if args.verb == "fuzz":
        fuzz(args.dest, args.cases)
        return 0
    if args.verb == "collect":
        collect(args.dest, args.jobs, args.only)
        return 0
    return compare(args.before, args.after)


if __name__ == "__main__":
    raise SystemExit(main())
