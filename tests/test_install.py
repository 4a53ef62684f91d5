"""A real, non-editable install works from any folder: models and scenarios are package data.

CI runs this with the rest of the suite.  To stay fast and offline it builds the
wheel with pip (build isolation, setuptools from pip's cache or index), installs
it with ``--no-deps`` into a fresh venv, and lends that venv the test
environment's site-packages for the dependencies (numpy, mujoco, ...) through a
``.pth`` line; headsim itself comes only from the wheel.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

pytestmark = pytest.mark.install


def _run(args: list[str], **kwargs) -> subprocess.CompletedProcess[str]:
    result = subprocess.run(args, capture_output=True, text=True, timeout=600, **kwargs)
    assert result.returncode == 0, (args, result.stdout[-3000:], result.stderr[-3000:])
    return result


def test_pip_install_runs_the_quick_start_from_another_folder(tmp_path: Path) -> None:
    # The sources as a user gets them (no build products of the checkout).
    source = tmp_path / "source"
    shutil.copytree(
        REPO / "headsim", source / "headsim", ignore=shutil.ignore_patterns("__pycache__")
    )
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(REPO / name, source / name)
    wheels = tmp_path / "wheels"
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(wheels), str(source)])
    (wheel,) = wheels.glob("headsim-*.whl")

    target = tmp_path / "venv"
    venv.EnvBuilder(with_pip=False).create(target)
    python = target / "bin" / "python"
    site = Path(
        _run(
            [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]
        ).stdout.strip()
    )
    (site / "_headsim_test_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps",
         "--no-index", str(wheel)]
    )  # fmt: skip

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.setdefault("MUJOCO_GL", "egl")
    where = _run(
        [str(python), "-c", "import headsim.sim.model as m, headsim.scenario.loading as s; "
         "print(m.__file__); print(m.MODELS_DIR); print(s.SCENARIOS_DIR)"],
        cwd=elsewhere, env=env,
    ).stdout.split()  # fmt: skip
    assert all(line.startswith(str(site)) for line in where), where  # the wheel, not the checkout

    headsim = str(target / "bin" / "headsim")
    listing = _run([headsim, "list"], cwd=elsewhere, env=env)
    assert "quickstart" in listing.stdout and "INVALID" not in listing.stdout
    _run([headsim, "run", "quickstart", "--quiet", "--out", "X"], cwd=elsewhere, env=env)
    assert (elsewhere / "X" / "results.json").is_file()
    _run([headsim, "snapshot", "--out", "snap"], cwd=elsewhere, env=env)
    assert (elsewhere / "snap" / "cam1.png").is_file()
