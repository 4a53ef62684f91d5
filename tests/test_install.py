"""Wheel and editable installs work from any folder: models/ and scenarios/ are package data.

CI runs this with the rest of the suite.  To stay fast and offline it builds with
pip (build isolation, setuptools from pip's cache or index), installs with
``--no-deps`` into a fresh venv, and lends that venv the test environment's
site-packages for the dependencies (numpy, mujoco, ...) through a ``.pth`` line;
headsim itself comes only from the copy of the sources under test.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path

import pytest

from headsim import __version__

REPO = Path(__file__).resolve().parent.parent

pytestmark = pytest.mark.install


def _run(args: list[str], **kwargs) -> subprocess.CompletedProcess[str]:
    result = subprocess.run(args, capture_output=True, text=True, timeout=600, **kwargs)
    assert result.returncode == 0, (args, result.stdout[-3000:], result.stderr[-3000:])
    return result


def _sources(tmp_path: Path) -> Path:
    """The sources as a user gets them (no build products of the checkout)."""
    source = tmp_path / "source"
    for folder in ("headsim", "models", "scenarios"):
        shutil.copytree(
            REPO / folder, source / folder, ignore=shutil.ignore_patterns("__pycache__")
        )
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy2(REPO / name, source / name)
    return source


def _venv(tmp_path: Path) -> tuple[Path, Path]:
    """A fresh venv that borrows the test environment's dependencies: (python, site-packages)."""
    target = tmp_path / "venv"
    venv.EnvBuilder(with_pip=False).create(target)
    python = target / "bin" / "python"
    site = Path(
        _run(
            [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]
        ).stdout.strip()
    )
    (site / "_headsim_test_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    return python, site


def _run_elsewhere(tmp_path: Path, python: Path) -> list[Path]:
    """Run the quick start, the listing and a snapshot from a folder outside the sources;
    the resolved paths of headsim's modules, models and scenarios."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.setdefault("MUJOCO_GL", "egl")
    where = _run(
        [str(python), "-c", "import headsim.sim.model as m, headsim.scenario.loading as s; "
         "print(m.__file__); print(m.MODELS_DIR); print(s.SCENARIOS_DIR)"],
        cwd=elsewhere, env=env,
    ).stdout.split()  # fmt: skip
    headsim = str(python.parent / "headsim")
    version = _run([headsim, "--version"], cwd=elsewhere, env=env)
    assert version.stdout == f"headsim {__version__}\n", version.stdout
    listing = _run([headsim, "list"], cwd=elsewhere, env=env)
    assert "quickstart" in listing.stdout and "INVALID" not in listing.stdout
    _run([headsim, "run", "quickstart", "--quiet", "--out", "X"], cwd=elsewhere, env=env)
    assert (elsewhere / "X" / "results.json").is_file()
    _run([headsim, "snapshot", "--out", "snap"], cwd=elsewhere, env=env)
    assert (elsewhere / "snap" / "cam1.png").is_file()
    return [Path(line).resolve() for line in where]


def _install_and_run(tmp_path: Path, *target: str) -> tuple[Path, list[Path]]:
    """pip-install ``target`` (pip's arguments) with --no-deps into a fresh venv and run it
    from another folder: the venv's resolved site-packages and :func:`_run_elsewhere`'s paths."""
    python, site = _venv(tmp_path)
    _run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps",
         *target]
    )  # fmt: skip
    return site.resolve(), _run_elsewhere(tmp_path, python)


def test_pip_install_runs_the_quick_start_from_another_folder(tmp_path: Path) -> None:
    source = _sources(tmp_path)
    wheels = tmp_path / "wheels"
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(wheels), str(source)])
    (wheel,) = wheels.glob("headsim-*.whl")
    assert wheel.name.startswith(f"headsim-{__version__}-"), wheel.name
    with zipfile.ZipFile(wheel) as archive:
        info = f"headsim-{__version__}.dist-info"
        license_text = archive.read(f"{info}/licenses/LICENSE").decode()
        metadata = archive.read(f"{info}/METADATA").decode()
    assert license_text == (REPO / "LICENSE").read_text()
    assert "Apache License\n                           Version 2.0" in license_text
    assert "License-Expression: Apache-2.0\n" in metadata
    assert "License-File: LICENSE\n" in metadata
    assert "Classifier: Intended Audience :: Science/Research\n" in metadata
    site, (module, models, scenarios) = _install_and_run(tmp_path, "--no-index", str(wheel))
    assert module.is_relative_to(site), module  # the wheel, not the checkout
    assert models == site / "headsim" / "models", models
    assert scenarios == site / "headsim" / "scenarios", scenarios


def test_editable_install_finds_the_top_level_models_and_scenarios(tmp_path: Path) -> None:
    source = _sources(tmp_path)
    _, (module, models, scenarios) = _install_and_run(tmp_path, "-e", str(source))
    source = source.resolve()
    assert module == source / "headsim" / "sim" / "model.py", module
    assert models == source / "models", models
    assert scenarios == source / "scenarios", scenarios
