"""The quick start's fast run with a recording, once for all the recording's test modules."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from headsim.cli import main


@pytest.fixture(scope="session")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("quickstart")
    rrd = out / "recording.rrd"
    assert (
        main(["run", "quickstart", "--fast", "--out", str(out), "--rrd", str(rrd), "--no-progress"])
        == 0
    )
    return rrd, json.loads((out / "results.json").read_text())
