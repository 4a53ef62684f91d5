"""Fuzzing the scenario reader: every mutated file is accepted or refused helpfully.

A seeded generator mutates the shipped scenario files (values replaced by
other types, huge integers, NaN-like and extreme numbers, keys renamed, lines
dropped or repeated, deep nesting, a byte-order mark, truncation, stray
characters).  Each outcome must be a valid :class:`Scenario` or a
:class:`ScenarioError` whose message names a key or a line, and says nothing
unhelpful (NaN angles, flat pixel indices).  No other exception may escape.
"""

from __future__ import annotations

import collections
import random
import re
import time
from pathlib import Path

from headsim.scenario.loading import load_scenario, scenario_files
from headsim.scenario.spec import Scenario
from headsim.scenario.tables import ScenarioError

#: Mutated files per test run (the issue asks for at least 2000 per CI run).
CASES = 2000
SEED = 20261201

BASES = {path.stem: path.read_text(encoding="utf-8") for path in scenario_files()}
#: Messages that say nothing a user can act on.
UNHELPFUL = re.compile(r"\bnan rad\b|flat index|object has no attribute|Traceback|\binf rad")

NASTY_VALUES = [
    "0", "-1", "1", "-0.0", "1e-12", "1e-300", "1e300", "-1e300", "nan", "inf", "-inf",
    "2147483648", "9223372036854775808", str(2**1024), str(-(2**1100)), "1" * 300,
    "true", "false", '""', '"x"', '"' + "a" * 500 + '"', "[]", "[1, 2]", "[[1, 2, 3]]",
    "{}", "{ a = 1 }", "1979-05-27T07:32:00Z", "0x7fffffff", "0.5", "4096", "10000",
    "1e-9", "1e9", "[0.0, 0.0, 0.0]", "[1e300, 0, 0]", "[nan, 0, 0]", "3.14159",
]  # fmt: skip
KEYS = [
    "width", "height", "kx", "ky", "k1", "k2", "baseline_m", "neck_a2_m", "neck_d1_m",
    "steps", "probe_steps", "seed", "noise_std", "targets", "vertical_spread_m", "procedure",
    "preset", "fit", "duration_s", "zoom", "bogus_key", "description",
]  # fmt: skip

VALUE_LINE = re.compile(r"^(\s*[\w.\"-]+\s*=\s*)(.+?)\s*(#.*)?$")


def _value_lines(lines: list[str]) -> list[int]:
    return [i for i, line in enumerate(lines) if VALUE_LINE.match(line)]


def mutate(text: str, rng: random.Random) -> tuple[str, str]:
    """One mutation of ``text``: (kind, new text)."""
    lines = text.split("\n")
    values = _value_lines(lines)
    kind = rng.choice(
        ["value", "value", "value", "scale", "scale", "delete", "duplicate", "rename", "truncate",
         "char", "deep", "huge_int", "bom", "table", "add_key"]
    )  # fmt: skip
    if kind in ("value", "scale", "rename", "add_key", "huge_int") and not values:
        kind = "delete"
    if kind == "value":
        i = rng.choice(values)
        head = VALUE_LINE.match(lines[i]).group(1)  # type: ignore[union-attr]
        lines[i] = head + rng.choice(NASTY_VALUES)
    elif kind == "scale":
        i = rng.choice(values)
        match = VALUE_LINE.match(lines[i])
        assert match is not None
        numbers = list(re.finditer(r"-?\d+(\.\d+)?(e-?\d+)?", match.group(2)))
        if numbers:
            number = rng.choice(numbers)
            factor = rng.choice([0.0, -1.0, 1e-9, 1e-3, 0.5, 2.0, 10.0, 1e3, 1e9])
            scaled = float(number.group()) * factor
            new = (
                str(int(scaled))
                if "." not in number.group() and abs(scaled) < 1e18
                else repr(scaled)
            )
            body = match.group(2)
            lines[i] = match.group(1) + body[: number.start()] + new + body[number.end() :]
    elif kind == "delete" and lines:
        del lines[rng.randrange(len(lines))]
    elif kind == "duplicate" and lines:
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
    elif kind == "rename":
        i = rng.choice(values)
        lines[i] = re.sub(r"^\s*[\w.\"-]+", rng.choice(KEYS), lines[i], count=1)
    elif kind == "truncate":
        return kind, text[: rng.randrange(len(text) + 1)]
    elif kind == "char":
        position = rng.randrange(len(text) + 1)
        return kind, text[:position] + rng.choice("[]{}=\"'#.,\n\\\x00\t") + text[position:]
    elif kind == "deep":
        depth = rng.choice([10, 49, 51, 200, 450, 1000, 5000])
        opening, closing = rng.choice([("[", "]"), ("{ a = ", " }")])
        lines.insert(rng.randrange(len(lines) + 1), f"deep = {opening * depth}1{closing * depth}")
    elif kind == "huge_int":
        i = rng.choice(values)
        head = VALUE_LINE.match(lines[i]).group(1)  # type: ignore[union-attr]
        lines[i] = head + rng.choice(["9" * 5000, str(2**1024), "-" + "9" * 4301, "9" * 4300])
    elif kind == "bom":
        return kind, "\ufeff" + text
    elif kind == "table":
        table = rng.choice(["[head]", "[cam1]", "[cam2]", "[experiment]", "[scene]", "[fast]",
                            "[[scene.targets]]", "[experiment.servo]", "[nonsense]", "[cam1.sub]"])  # fmt: skip
        lines.insert(rng.randrange(len(lines) + 1), f"{table}\n{rng.choice(KEYS)} = "
                     f"{rng.choice(NASTY_VALUES)}")  # fmt: skip
    elif kind == "add_key":
        i = rng.choice(values) + 1
        lines.insert(i, f"{rng.choice(KEYS)} = {rng.choice(NASTY_VALUES)}")
    return kind, "\n".join(lines)


def test_mutated_scenario_files_are_accepted_or_refused_naming_a_key_or_line(
    tmp_path: Path,
) -> None:
    rng = random.Random(SEED)
    outcomes: collections.Counter[str] = collections.Counter()
    slowest = (0.0, "")
    names = sorted(BASES)
    for case in range(CASES):
        base = names[case % len(names)]
        text = BASES[base]
        kind, text = mutate(text, rng)
        if rng.random() < 0.3:  # a second mutation on a third of the cases
            kind2, text = mutate(text, rng)
            kind = f"{kind}+{kind2}"
        path = tmp_path / f"case{case}.toml"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        start = time.perf_counter()
        try:
            scenario = load_scenario(path)
        except ScenarioError as err:
            message = str(err)
            names_line = re.search(r"\bline \d+", message) is not None
            assert err.field or names_line, (kind, message, text)
            assert not UNHELPFUL.search(message), (kind, message, text)
            assert len(message) < 1000, (kind, message[:300])
            outcomes["refused naming a key" if err.field else "refused naming a line"] += 1
        else:
            assert isinstance(scenario, Scenario)
            outcomes["accepted"] += 1
        elapsed = time.perf_counter() - start
        if elapsed > slowest[0]:
            slowest = (elapsed, f"{base} {kind}")
        path.unlink()
    print(f"\nfuzz: {CASES} cases: {dict(outcomes)}; slowest {slowest[0]:.3f} s ({slowest[1]})")
    assert sum(outcomes.values()) == CASES
    assert outcomes["accepted"] > 0 and outcomes["refused naming a key"] > 0
    assert outcomes["refused naming a line"] > 0
