"""Sweep files: grids, seeded random samples, and bad files named by field."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from headsim.studies.sweep_spec import SweepError, load_sweep

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture
def grid(tmp_path: Path) -> Path:
    for name in ("sweep_base.toml", "sweep_grid.toml"):
        shutil.copy(DATA / name, tmp_path / name)
    return tmp_path / "sweep_grid.toml"


def test_grid_expands_to_every_combination(grid: Path) -> None:
    spec = load_sweep(grid)
    assert [j.params for j in spec.jobs] == [
        {"head.baseline_m": 0.12, "cam1.noise_std": 0.0},
        {"head.baseline_m": 0.12, "cam1.noise_std": 2.0},
        {"head.baseline_m": 0.18, "cam1.noise_std": 0.0},
        {"head.baseline_m": 0.18, "cam1.noise_std": 2.0},
    ]
    assert len({j.id for j in spec.jobs}) == 4
    assert load_sweep(grid).jobs == spec.jobs  # ids are stable


def test_random_sample_is_seeded(tmp_path: Path) -> None:
    shutil.copy(DATA / "sweep_base.toml", tmp_path / "sweep_base.toml")
    text = 'description = "r"\nscenario = "sweep_base.toml"\n[random]\ncount = 5\nseed = 3\n[random.fields]\n"head.baseline_m" = [0.1, 0.2]\nseed = [0, 99]\n'
    (tmp_path / "r.toml").write_text(text)
    first, second = load_sweep(tmp_path / "r.toml"), load_sweep(tmp_path / "r.toml")
    assert [j.params for j in first.jobs] == [j.params for j in second.jobs]
    assert all(0.1 <= j.params["head.baseline_m"] <= 0.2 for j in first.jobs)
    assert all(isinstance(j.params["seed"], int) for j in first.jobs)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            'description = "x"\nscenario = "sweep_base.toml"\n[grid]\nfoo = 1\n',
            "grid.foo: must be a non-empty list",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\n[grid]\n"cam1.bogus" = [1]\n',
            "cam1.bogus: unknown key",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\n[grid]\n"head.baseline_m" = [-1.0]\n',
            "head.baseline_m",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\nworkers = 3\n[grid]\nseed = [1]\n',
            "workers: unknown key",
        ),
        (
            'description = "x"\nscenario = "nowhere"\n[grid]\nseed = [1]\n',
            "scenario: .*no such scenario file",
        ),
        ('description = "x"\nscenario = "sweep_base.toml"\n', "needs exactly one of"),
        (
            'description = "x"\nscenario = "sweep_base.toml"\n[random]\ncount = 2\n[random.fields]\nseed = [5, 1]\n',
            "not a range",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\nbackend = "gpu"\n[grid]\nseed = [1]\n',
            r"backend: 'gpu' is not a back-end \(allowed: classic, batch\)",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\nbackend = "batch"\n[batch]\nworlds = 0\n[grid]\nseed = [1]\n',
            r"batch.worlds: 0 is not allowed \(allowed: an integer from 1 to 4096\)",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\nbackend = "batch"\n[batch]\nsamples_per_pixel = 2\n[grid]\nseed = [1]\n',
            r"batch.samples_per_pixel: is not used: lockstep draws each head at its own fidelity .*\(allowed: worlds, device\)",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\nbackend = "batch"\n[batch]\ndevice = "tpu"\n[grid]\nseed = [1]\n',
            r"batch.device: 'tpu' is not a device \(allowed: cpu, cuda\)",
        ),
        (
            'description = "x"\nscenario = "sweep_base.toml"\n[batch]\nworlds = 4\n[grid]\nseed = [1]\n',
            'batch: is read only with backend = "batch"',
        ),
    ],
)
def test_bad_sweep_files_name_the_field(tmp_path: Path, text: str, message: str) -> None:
    shutil.copy(DATA / "sweep_base.toml", tmp_path / "sweep_base.toml")
    (tmp_path / "bad.toml").write_text(text)
    with pytest.raises(SweepError, match=message):
        load_sweep(tmp_path / "bad.toml")
