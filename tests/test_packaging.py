"""pyproject.toml's explicit package list stays in step with the tree.

setuptools is given the packages by name (``packages.find`` beside ``package-dir``
silently drops the mapped data packages), so a new folder of modules under
headsim/ must be added to the list, and the top-level models/ and scenarios/
must stay mapped to ``headsim.models`` and ``headsim.scenarios`` with package
data that covers every file in them.
"""

from __future__ import annotations

import ast
import tomllib
from fnmatch import fnmatch
from pathlib import Path

import pytest

from headsim import __version__, version
from headsim.cli import main
from headsim.scenario.loading import SCENARIOS_DIR
from headsim.sim.model import MODELS_DIR

REPO = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())
SETUPTOOLS = PYPROJECT["tool"]["setuptools"]
PACKAGES: list[str] = SETUPTOOLS["packages"]
PACKAGE_DIR: dict[str, str] = SETUPTOOLS["package-dir"]
#: The top-level data folders and the package each is installed as.
DATA_PACKAGES = {"headsim.models": "models", "headsim.scenarios": "scenarios"}


def _folder(package: str) -> Path:
    """The folder setuptools builds ``package`` from (its longest ``package-dir`` prefix)."""
    parts = package.split(".")
    for cut in range(len(parts), 0, -1):
        prefix = ".".join(parts[:cut])
        if prefix in PACKAGE_DIR:
            return REPO / PACKAGE_DIR[prefix] / Path(*parts[cut:])
    return REPO / PACKAGE_DIR.get("", ".") / Path(*parts)


def test_the_package_list_is_explicit() -> None:
    assert isinstance(PACKAGES, list)
    assert "packages" not in SETUPTOOLS.get("find", {})
    assert len(PACKAGES) == len(set(PACKAGES)), sorted(PACKAGES)


def test_every_folder_of_modules_under_headsim_is_listed() -> None:
    folders = {
        path.parent for path in (REPO / "headsim").rglob("*.py") if "__pycache__" not in path.parts
    }
    found = {".".join(folder.relative_to(REPO).parts) for folder in folders}
    listed = {package for package in PACKAGES if package not in DATA_PACKAGES}
    assert found == listed, (
        f"missing from pyproject.toml: {sorted(found - listed)}; "
        f"listed but not in the tree: {sorted(listed - found)}"
    )


def test_every_listed_package_exists() -> None:
    for package in PACKAGES:
        folder = _folder(package)
        assert (folder / "__init__.py").is_file(), (package, folder)


def test_models_and_scenarios_are_mapped_top_level_folders() -> None:
    for package, folder in DATA_PACKAGES.items():
        assert package in PACKAGES
        assert PACKAGE_DIR[package] == folder
        assert _folder(package) == REPO / folder
    assert not (REPO / "headsim" / "models").exists()
    assert not (REPO / "headsim" / "scenarios").exists()


def test_package_data_covers_every_model_and_scenario_file() -> None:
    data: dict[str, list[str]] = SETUPTOOLS["package-data"]
    for package, folder in DATA_PACKAGES.items():
        files = [p for p in (REPO / folder).iterdir() if p.is_file() and p.suffix != ".py"]
        assert files, folder
        for path in files:
            assert any(fnmatch(path.name, pattern) for pattern in data[package]), (
                f"{folder}/{path.name} is not in [tool.setuptools.package-data] {package!r}"
            )


def test_package_data_covers_the_campaigns_experiment_files() -> None:
    patterns: list[str] = SETUPTOOLS["package-data"]["headsim.studies"]
    files = sorted((REPO / "headsim" / "studies").glob("*.toml"))
    assert [p.name for p in files] == [
        "bench_cases.toml",
        "reproduce_experiments.toml",
        "study_experiments.toml",
    ]
    assert all(any(fnmatch(p.name, pattern) for pattern in patterns) for p in files)


def test_the_installed_package_finds_the_checkouts_models_and_scenarios() -> None:
    # The suite runs on an editable install (make setup); a stale one (installed
    # before pyproject.toml changed) fails here: run `make setup` again.
    assert MODELS_DIR.resolve() == REPO / "models"
    assert SCENARIOS_DIR.resolve() == REPO / "scenarios"
    assert (MODELS_DIR / "head.xml").is_file()
    assert (SCENARIOS_DIR / "quickstart.toml").is_file()


def test_the_license_file_and_the_metadata_ship_with_the_package() -> None:
    project = PYPROJECT["project"]
    assert project["license"] == "Apache-2.0"
    assert project["license-files"] == ["LICENSE"]
    text = (REPO / "LICENSE").read_text()
    assert "Apache License" in text and "END OF TERMS AND CONDITIONS" in text
    assert len(text.splitlines()) > 190  # the whole text, not a pointer to it
    classifiers = project["classifiers"]
    assert "Intended Audience :: Science/Research" in classifiers
    # A license expression and a License :: classifier together are refused by setuptools.
    assert not [c for c in classifiers if c.startswith("License ::")]
    assert project["dynamic"] == ["version"]
    assert SETUPTOOLS["dynamic"]["version"] == {"attr": "headsim.version.__version__"}


def test_version_prints_the_package_version_and_exits_0(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with pytest.raises(SystemExit) as done:  # argparse's exit, as for --help
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out == f"headsim {__version__}\n"
    assert __version__.count(".") == 2 and all(p.isdigit() for p in __version__.split("."))


def test_no_module_of_the_package_imports_the_package_root_for_a_name() -> None:
    """The version has one home below every layer (headsim/version.py): a module that
    took it, or anything else, from ``headsim`` itself would import the lazy top-level
    API (and the whole package above it) from below."""
    package = REPO / "headsim"
    found = []
    for path in sorted(package.rglob("*.py")):
        if path == package / "__init__.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found += [
                    f"{path.relative_to(REPO)}: import {a.name}"
                    for a in node.names
                    if a.name == "headsim"
                ]
            elif isinstance(node, ast.ImportFrom) and node.module == "headsim" and node.level == 0:
                found += [
                    f"{path.relative_to(REPO)}: from headsim import {a.name}"
                    for a in node.names
                    if not (package / a.name).is_dir() and not (package / f"{a.name}.py").is_file()
                ]
    assert found == [], found
    assert version.__version__ == __version__
