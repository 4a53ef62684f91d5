"""MkDocs hook: the reference pages made from the code at build time.

``mkdocs.yml`` names this file under ``hooks``; each page below is added to the
site as a generated file (nothing generated is committed):

- ``reference/scenario-keys.md``: every key the scenario loader accepts, from the
  declarations (:mod:`headsim.scenario.key_reference`);
- ``reference/results-json.md``: every key of results.json, from
  :mod:`headsim.runs.results_reference`;
- ``reference/command-line.md``: every command's ``--help``, from the parser;
- ``reference/exit-codes.md``: the exit-code contract (:mod:`headsim.errors`).

and a page's ``<!-- generated:NAME -->`` is replaced by what ``GENERATED[NAME]`` makes:
the package's version (the home page), the table of shipped scenarios (how to write one),
the shipped heads (run your own head) and their designs (the model).
"""

from __future__ import annotations

import argparse
import os
import re
from typing import Any

from mkdocs.structure.files import File, Files

from headsim import __version__
from headsim.cli.parser import build_parser
from headsim.errors import EXIT_MEANINGS, ExitCode
from headsim.runs.results_reference import (
    CALIBRATION_FILE_FIELDS,
    RESULTS_FIELDS,
    experiment_fields,
)
from headsim.scenario.key_reference import accepted_keys
from headsim.scenario.loading import load_scenario, scenario_files
from headsim.sim.heads import REGISTRY, SHIPPED
from headsim.sim.model import design, has_own_cameras


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def scenario_keys_page() -> str:
    """Every accepted key as one table per top-level table."""
    out = [
        "# Scenario keys\n",
        "Every key the scenario loader accepts, made at build time from its declaration: "
        "its type, what is allowed, default and meaning (the loader reads the key through "
        "the same declaration, `headsim.scenario.key_reference`). Lengths m, angles rad, pixels as "
        "OpenCV's; `[]` stands for any entry of an array of tables. *required* means "
        "the file must give it where its table is read; a default that other keys set "
        "(a preset, the image size) says so. How to write a file: "
        "[Write a scenario](../how-to/write-a-scenario.md).\n",
    ]
    keys = accepted_keys()
    groups: dict[str, list[Any]] = {}
    for key in keys:
        groups.setdefault(key.path.split(".")[0].split("[")[0], []).append(key)
    for group, members in groups.items():
        out.append(
            f"\n## `{group}`\n\n| key | type | allowed | default | meaning |\n|---|---|---|---|---|"
        )
        for k in members:
            kind = k.kind or "see meaning"
            default = (
                "-"
                if k.kind in ("table", "tables", "")
                else (f"`{k.default}`" if k.default else "*required*")
            )
            if k.default == "depends on other keys":
                default = "depends on other keys"
            out.append(
                f"| `{k.path}` | {kind} | {_cell(k.allowed) or '-'} | {_cell(default)} | "
                f"{_cell(k.description)} |"
            )
    return "\n".join(out) + "\n"


_RESULTS_INTRO = (
    "# results.json\n\n"
    "Written atomically at the end of a run (also when a measurement failed; not when the "
    "input was bad or the run was interrupted). It holds no wall time or date: the same "
    "scenario, seed and software give the same bytes. SI units; NaN is written as `null`. "
    "Made at build time from `headsim.runs.results_reference`: `a[]` stands for each entry "
    "of the list `a`, `a.*` for each key of a table whose keys are data (a knowledge, a "
    "phase); a key whose keys are not listed is described as a whole.\n"
)


def _field_tables(fields: dict[str, str], top: str) -> list[str]:
    """One table per path whose keys are listed: the top level first, then in order."""
    parents: dict[str, list[str]] = {}
    for path in fields:
        head, sep, _ = path.rpartition(".")
        parent = head if sep else ""
        parents.setdefault(parent, []).append(path)
    out = []
    for parent, children in parents.items():
        out.append(f"\n## `{parent}`\n" if parent else f"\n## {top}\n")
        out.append("| key | meaning |\n|---|---|")
        for path in children:
            out.append(f"| `{path.rpartition('.')[2]}` | {_cell(fields[path])} |")
    return out


def results_json_page() -> str:
    """Every key of results.json, and each procedure's ``experiment`` keys."""
    out = [_RESULTS_INTRO, *_field_tables(RESULTS_FIELDS, "Top level")]
    out.append(
        "\n## `experiment` by procedure\n\nBeside `procedure`, each procedure's own keys "
        "(its result's fields; the `results` its module declares in its `Procedure`)."
    )
    for procedure, fields in experiment_fields().items():
        out.append(f"\n### `{procedure}`\n")
        if not fields:
            out.append("No keys beyond its measurements.")
            continue
        out.append("| key | meaning |\n|---|---|")
        out.extend(f"| `{key}` | {_cell(text)} |" for key, text in fields.items())
    out.append(
        "\n## The calibration file (`head.json`)\n\n`headsim calibrate SCENARIO --out "
        "head.json` writes it and `[experiment.calibration] from` reads it (`.` separates a "
        "table's keys):\n\n| key | meaning |\n|---|---|"
    )
    out.extend(f"| `{key}` | {_cell(text)} |" for key, text in CALIBRATION_FILE_FIELDS.items())
    return "\n".join(out) + "\n"


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:  # argparse keeps its subcommands only here
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def command_line_page() -> str:
    """``headsim --help`` and every command's ``--help``, as the parser prints them."""
    os.environ.setdefault("COLUMNS", "100")
    parser = build_parser()
    out = [
        "# Command line\n",
        "Made at build time from the argument parser (`headsim.cli.parser.build_parser`); "
        "`headsim COMMAND --help` prints the same. Every command ends with one of the "
        "[exit codes](exit-codes.md); `--debug` anywhere adds a traceback to an error, "
        "`--quiet` anywhere leaves only errors on stderr.\n",
        "```text\n" + parser.format_help().rstrip() + "\n```\n",
    ]
    for name, sub in _subcommands(parser).items():
        out.append(f"## `headsim {name}`\n\n```text\n{sub.format_help().rstrip()}\n```\n")
    return "\n".join(out)


def exit_codes_page() -> str:
    """The exit-code contract, from :data:`headsim.errors.EXIT_MEANINGS` (a code without a
    meaning fails the build)."""
    rows = "\n".join(
        f"| {int(code)} | `{code.name}` | {EXIT_MEANINGS[code]} |" for code in ExitCode
    )
    return (
        "# Exit codes\n\nThe same for every command (`headsim.errors.ExitCode`). Every failure "
        "ends with one line `headsim: error: ...` on stderr and no Python traceback "
        "(`--debug` adds it).\n\n| code | name | meaning |\n|---|---|---|\n" + rows + "\n"
    )


def scenarios_table() -> str:
    """Every shipped scenario (scenarios/*.toml): its name, head, procedure and description."""
    rows = ["| scenario | head | procedure | what |", "|---|---|---|---|"]
    for path in scenario_files():
        scenario = load_scenario(path)  # a shipped file that does not load fails the build
        rows.append(
            f"| `{path.stem}` | {scenario.settings.head.name} | "
            f"`{scenario.experiment.procedure}` | {_cell(scenario.description)} |"
        )
    return "\n".join(rows)


def heads_table() -> str:
    """Every shipped head (:data:`headsim.sim.heads.REGISTRY`): its name and its line."""
    rows = ["| `head.model` | what |", "|---|---|"]
    for name, line in SHIPPED.items():
        rows.append(f"| `{name}`{' (default)' if name == 'paper' else ''} | {_cell(line)} |")
    return "\n".join(rows)


def _code(*names: str | None) -> str:
    return ", ".join(f"`{n}`" for n in names if n is not None)


def head_designs_table() -> str:
    """Every shipped head's joints, eyes, baseline and cameras, read from its compiled
    model at all joints zero (a shipped file that fails its checks fails the build)."""
    rows = [
        "| head | file | neck joints | eyes | baseline | cameras |",
        "|---|---|---|---|---|---|",
    ]
    for name, head in REGISTRY.items():
        m, designed = head.mapping, design(head)
        held = f"; {_code(*m.held)} held at zero" if m.held else ""
        if designed.neck.order == "pitch_yaw":
            neck = (
                f"{_code(m.neck_pitch)} at the base, then {_code(m.neck_yaw)} ((H10): H "
                f"{designed.neck.forward_m * 1e3:g} mm ahead of the yaw axis, "
                f"{(designed.neck_d1_m + designed.neck_a2_m) * 1e3:g} mm above the pitch axis)"
            )
        else:
            neck = (
                f"{_code(m.neck_yaw, m.neck_pitch)} (d1 {designed.neck_d1_m:g} m, "
                f"a2 {designed.neck_a2_m:g} m)"
            )
        pans = _code(m.left_eye, m.right_eye)
        eyes = {
            "coupled": f"coupled: one motor turns {_code(m.left_eye)}, {_code(m.right_eye)} follows",
            "independent": f"independent: {pans}, a motor each",
            "version_vergence": f"version and vergence ({_code(m.version, m.vergence)}) "
            f"over {pans}",
        }[m.eyes]
        camera = designed.cameras[0]
        cameras = f"{_code(*m.cameras)}: {camera.width}x{camera.height}, f = {camera.fx_px:.2f} px"
        if has_own_cameras(head):
            cameras += ", kept under every preset"
        file = "head.xml" if head.path is None else head.path.name
        rows.append(
            f"| `{name}`{' (default)' if name == 'paper' else ''} | `{file}` | {neck}{held} | "
            f"{eyes} | {designed.baseline_m * 1e3:g} mm | {cameras} |"
        )
    return "\n".join(rows)


GENERATED = {
    "version": lambda: __version__,
    "scenarios": scenarios_table,
    "heads": heads_table,
    "head-designs": head_designs_table,
}
MARKER = re.compile(r"<!-- generated:(?P<name>[\w-]+) -->")


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    """Each ``<!-- generated:NAME -->`` replaced by what it names."""

    def one(match: re.Match[str]) -> str:
        if match["name"] not in GENERATED:
            raise ValueError(f"{page.file.src_uri}: unknown generated block {match[0]!r}")
        return GENERATED[match["name"]]()

    return MARKER.sub(one, markdown)


PAGES = {
    "reference/scenario-keys.md": scenario_keys_page,
    "reference/results-json.md": results_json_page,
    "reference/command-line.md": command_line_page,
    "reference/exit-codes.md": exit_codes_page,
}


def on_files(files: Files, config: Any) -> Files:
    """Add the generated pages to the site."""
    for uri, make in PAGES.items():
        files.append(File.generated(config, uri, content=make()))
    return files
