"""The suite's tiers (tests/conftest.py): every test in exactly one; a fast test never renders."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from headsim.sim import render

pytestmark = pytest.mark.fast
ROOT = Path(__file__).resolve().parents[1]
#: Collects the suite (one pytest process) and prints each test's tier markers as JSON.
COLLECT = """
import json, pytest

class Tiers:
    def pytest_collection_finish(self, session):
        tiers = {item.nodeid: [m for m in ("fast", "render", "e2e") if item.get_closest_marker(m)]
                 for item in session.items}
        print("TIERS " + json.dumps(tiers))

pytest.main(["--collect-only", "-q", "-p", "no:cacheprovider"], plugins=[Tiers()])
"""


def test_every_test_is_in_exactly_one_tier() -> None:
    done = subprocess.run(
        [sys.executable, "-c", COLLECT], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    line = next((x for x in done.stdout.splitlines() if x.startswith("TIERS ")), None)
    assert line is not None, done.stdout[-2000:] + done.stderr[-2000:]
    tiers: dict[str, list[str]] = json.loads(line.removeprefix("TIERS "))
    assert len(tiers) > 1000
    assert {test: marks for test, marks in tiers.items() if len(marks) != 1} == {}
    # By directory unless a test says otherwise.
    assert tiers["tests/test_tiers.py::test_every_test_is_in_exactly_one_tier"] == ["fast"]
    assert tiers["tests/run/test_lazy_rerun.py::test_import_headsim_does_not_import_rerun"] == [
        "fast"
    ]
    for directory, tier in (("geometry", "fast"), ("sim", "render"), ("cli", "e2e")):
        assert {marks[0] for t, marks in tiers.items() if t.startswith(f"tests/{directory}/")} == {
            tier
        }


def test_a_fast_test_that_renders_fails() -> None:
    with pytest.raises(pytest.fail.Exception, match=re.escape("mark it @pytest.mark.render")):
        render._acquire("scene", None)  # type: ignore[arg-type]  # refused before it is read
