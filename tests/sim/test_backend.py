"""Choosing MUJOCO_GL before mujoco loads, in fresh interpreters (the choice is made on import)."""

from __future__ import annotations

import ctypes.util
import json
import os
import subprocess
import sys

import pytest

PROBE = (
    "import json, os; import headsim; from headsim.sim import backend\n"
    "try:\n"
    "    checked, problem = backend.check_backend(), None\n"
    "except backend.RenderBackendError as err:\n"
    "    checked, problem = None, str(err)\n"
    "print(json.dumps({'gl': os.environ['MUJOCO_GL'], 'checked': checked, 'problem': problem}))"
)


def probe(mujoco_gl: str | None, **extra: str) -> dict[str, str | None]:
    """``import headsim`` under ``MUJOCO_GL=mujoco_gl`` (unset: None), then check_backend."""
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY")}
    env.update(extra)
    if mujoco_gl is not None:
        env["MUJOCO_GL"] = mujoco_gl
    result = subprocess.run(
        [sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def test_unset_picks_egl_here_and_it_checks_out() -> None:
    # This machine has libEGL (the suite renders with it).
    assert probe(None) == {"gl": "egl", "checked": "egl", "problem": None}
    assert probe("EGL") == {"gl": "EGL", "checked": "egl", "problem": None}


def test_an_unknown_value_is_disabled_at_import_and_named_when_rendering() -> None:
    found = probe("vulkan")
    assert found["gl"] == "disable"  # mujoco still imports for work that does not render
    assert found["checked"] is None
    assert "MUJOCO_GL='vulkan' is not a backend headsim can render with; allowed: egl, " in str(
        found["problem"]
    )
    assert "apt-get install libegl1" in str(found["problem"])


@pytest.mark.parametrize("value", ["off", "disable", "0"])
def test_rendering_turned_off_says_how_to_turn_it_on(value: str) -> None:
    found = probe(value)
    assert found["gl"] == value and found["checked"] is None
    assert f"MUJOCO_GL={value} turns rendering off" in str(found["problem"])


def test_glfw_without_a_display_points_to_off_screen_backends() -> None:
    found = probe("glfw")
    assert found["checked"] is None
    if ctypes.util.find_library("GL") is None:  # its library is checked first
        expected = "MUJOCO_GL=glfw but libGL is not installed: apt-get install libgl1 "
    else:
        expected = "MUJOCO_GL=glfw needs a display (DISPLAY is not set): use MUJOCO_GL=egl or "
    assert str(found["problem"]).startswith(expected), found
