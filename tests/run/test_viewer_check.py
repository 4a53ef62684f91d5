"""The viewer check's command line (tests/run/viewer/check.py): usage errors and exit 3 when the
viewer cannot be run, with no screenshot written."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.run.viewer.check import main


def test_a_recording_or_a_url_is_required(capsys) -> None:
    with pytest.raises(SystemExit) as caught:
        main([])
    assert caught.value.code == 2
    assert "give a recording or --url" in capsys.readouterr().err


def test_a_viewer_that_cannot_serve_the_file_is_exit_3_and_writes_nothing(
    tmp_path: Path, capsys
) -> None:
    png = tmp_path / "viewer.png"
    assert main([str(tmp_path / "absent.rrd"), "--png", str(png)]) == 3
    err = capsys.readouterr().err
    assert err.startswith("viewer_check: error: ") and err.count("\n") == 1
    assert not png.exists()
