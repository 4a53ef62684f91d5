"""The scenario commands (cli/scenarios.py): run and list refuse bad files with exit 2,
list describes every scenario, and the progress shown follows the flags."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest
from scenario.helpers import MINIMAL, write_scenario

from headsim.cli import main
from headsim.cli.scenarios import progress_observer
from headsim.scenario.loading import load_scenario, scenario_files
from headsim.scenario.tables import ScenarioError

FILES = scenario_files()


def test_run_with_a_bad_file_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_scenario(tmp_path, MINIMAL.replace("0.6]", "-0.6]"))
    out, rrd = tmp_path / "out", tmp_path / "rec" / "run.rrd"
    assert main(["run", str(path), "--out", str(out), "--rrd", str(rrd)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"headsim: error: {path}: scene.targets[0]: target at")
    assert not out.exists() and not rrd.parent.exists()
    assert main(["run", "quickstart", "--seed", "-3", "--out", str(out)]) == 2
    assert "seed: -3 is out of range" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize(
    ("seed", "said"),
    [
        ("a", "seed: must be an integer, got string 'a'"),
        (True, "seed: must be an integer, got boolean True"),
        (2**32, "seed: 4294967296 is out of range"),
    ],
)
def test_a_seed_given_from_outside_the_file_is_checked_as_the_files_own(
    seed: object, said: str
) -> None:
    # --seed, a sweep's seed field, load_scenario(seed=...): one declaration's message.
    with pytest.raises(ScenarioError) as caught:
        load_scenario("quickstart", seed=seed)  # type: ignore[arg-type]
    assert said in str(caught.value)
    assert str(caught.value).endswith("(allowed: an integer from 0 to 4294967295)")


def test_list_shows_every_scenario_with_its_head_and_description(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^  name\s+head\s+description$", out, re.M)
    heads = set()
    for path in FILES:
        scenario = load_scenario(path)
        head, description = scenario.settings.head.name, scenario.description
        heads.add(head)
        assert re.search(rf"^  {path.stem}\s+{head}\s+{re.escape(description)}$", out, re.M)
    assert {"paper", "independent_eyes"} <= heads


def test_list_flags_an_invalid_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write_scenario(tmp_path, MINIMAL, "good.toml")
    write_scenario(tmp_path, MINIMAL + "[head]\nbaseline_m = 0\n", "broken.toml")
    assert main(["list", "--dir", str(tmp_path)]) == 2
    out = capsys.readouterr().out
    assert "good" in out and "a test" in out
    assert (
        re.search(r"^  broken {3,}INVALID:", out, re.M)
        and "head.baseline_m: 0 is out of range" in out
    )


def test_progress_is_shown_unless_quiet_or_turned_off() -> None:
    assert progress_observer(argparse.Namespace(no_progress=True), 5, "fixations") is None
    assert progress_observer(argparse.Namespace(quiet=True), 5, "fixations") is None
    shown = progress_observer(argparse.Namespace(), 5, "fixations")
    assert shown is not None and shown.counter.total == 5
