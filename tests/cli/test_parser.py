"""The command line's arguments, and what ``headsim --help`` loads."""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from headsim.cli.estimate import estimate_command
from headsim.cli.parser import build_parser, positive_int, preset_name
from headsim.cli.scenarios import calibrate_command, list_command, run_command
from headsim.cli.snapshot import snapshot_command
from headsim.cli.studies import bench_command, reproduce_command, study_command, sweep_command
from headsim.errors import EXIT_CODES_HELP
from headsim.sim.settings import PRESETS


def _commands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def test_every_command_reaches_its_function_and_states_the_exit_codes() -> None:
    parser = build_parser(with_study=False)
    commands = _commands(parser)
    expected = {
        "run": run_command,
        "calibrate": calibrate_command,
        "reproduce": reproduce_command,
        "list": list_command,
        "snapshot": snapshot_command,
        "sweep": sweep_command,
        "study": study_command,
        "bench": bench_command,
        "estimate": estimate_command,
    }
    assert set(commands) == set(expected)
    for name, sub in commands.items():
        assert sub.get_default("func") is expected[name], name
        assert sub.epilog == EXIT_CODES_HELP or name in ("calibrate", "reproduce")
    assert parser.epilog == EXIT_CODES_HELP
    args = parser.parse_args(["snapshot", "--out", "x", "--preset", "paper", "--eye", "0.1"])
    assert (args.func, args.preset, args.eye, args.scene) == (
        snapshot_command,
        "paper",
        0.1,
        "default",
    )


def test_bad_arguments_are_usage_errors(capsys: pytest.CaptureFixture[str]) -> None:
    parser = build_parser(with_study=False)
    with pytest.raises(SystemExit) as stop:
        parser.parse_args(["snapshot", "--out", "x", "--preset", "toy"])
    assert stop.value.code == 2
    assert (
        "argument --preset: 'toy' is not a preset (allowed: ideal, paper, realistic)"
        in capsys.readouterr().err
    )
    assert [preset_name(name) for name in PRESETS] == list(PRESETS)
    assert positive_int("3") == 3
    with pytest.raises(
        argparse.ArgumentTypeError, match=r"0 is not allowed \(allowed: an integer >= 1\)"
    ):
        positive_int("0")
    with pytest.raises(argparse.ArgumentTypeError, match="'x' is not an integer"):
        positive_int("x")


def test_the_study_options_load_only_for_the_study() -> None:
    bare = _commands(build_parser(with_study=False))["study"]
    full = _commands(build_parser(with_study=True))["study"]
    assert len(full._actions) > len(bare._actions)
    assert full.description and not bare.description


def test_help_loads_no_numerical_or_rendering_library() -> None:
    result = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "headsim.cli", "--help"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0
    assert "usage: headsim" in result.stdout
    loaded = {line.split("|")[-1].strip().split(".")[0] for line in result.stderr.splitlines()}
    assert "headsim" in loaded
    assert not loaded & {
        "numpy", "scipy", "matplotlib", "mujoco", "cv2", "rerun", "dask", "gymnasium", "mcap"
    }  # fmt: skip
