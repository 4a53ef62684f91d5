"""A shipped scenario's fast variant run by the command line, its typed result kept."""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from dataclasses import dataclass
from pathlib import Path

import pytest

from headsim.cli import main
from headsim.runs.result import RunResult


@dataclass(frozen=True)
class ShippedRun:
    """A shipped scenario's fast variant as ``headsim run NAME --fast`` ran it."""

    code: int
    #: What the command printed (stdout).
    out: str
    #: Its ``--out`` directory (results.json, summary.txt, timing.json).
    directory: Path
    #: What the runner returned to the command.
    result: RunResult


def run_shipped(name: str, directory: Path) -> ShippedRun:
    """``headsim run NAME --fast --out DIRECTORY`` in-process, keeping the runner's result."""
    from headsim.runs import runner

    real = runner.run_scenario
    results: list[RunResult] = []

    def kept(*args: object, **kwargs: object) -> RunResult:
        results.append(real(*args, **kwargs))  # type: ignore[arg-type]
        return results[-1]

    printed = io.StringIO()
    with pytest.MonkeyPatch.context() as patch, redirect_stdout(printed):
        patch.setattr(runner, "run_scenario", kept)
        code = main(["run", name, "--fast", "--out", str(directory), "--no-progress"])
    assert len(results) == 1, (name, code, printed.getvalue())
    return ShippedRun(code, printed.getvalue(), directory, results[0])
