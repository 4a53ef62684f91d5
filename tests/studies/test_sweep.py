"""Sweeps on a local process pool and on a local Dask cluster: same answers, resumable, crash-proof."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import pytest

from headsim.cli import main
from headsim.studies.jobs import read_log
from headsim.studies.sweep import CRASH_ENV, run_sweep
from headsim.studies.sweep_spec import load_sweep

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture
def grid(tmp_path: Path) -> Path:
    for name in ("sweep_base.toml", "sweep_grid.toml"):
        shutil.copy(DATA / name, tmp_path / name)
    return tmp_path / "sweep_grid.toml"


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as handle:
        return list(csv.DictReader(handle))


def test_local_pool_and_dask_cluster_give_the_same_aggregate(grid: Path, tmp_path: Path) -> None:
    from dask.distributed import LocalCluster

    spec = load_sweep(grid)
    local = run_sweep(spec, tmp_path / "local", workers=2, progress=False)
    assert local.ran == 4 and not local.failed
    with LocalCluster(
        n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None
    ) as cluster:
        dask = run_sweep(
            spec, tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False
        )
    assert dask.ran == 4
    assert (tmp_path / "local" / "aggregate.csv").read_text() == (
        tmp_path / "dask" / "aggregate.csv"
    ).read_text()
    rows = _rows(tmp_path / "local" / "aggregate.csv")
    assert [r["status"] for r in rows] == ["ok"] * 4
    assert all(float(r["rms_error_pct_depth"]) < 0.5 for r in rows)
    assert (tmp_path / "local" / "error_vs_head_baseline_m.png").stat().st_size > 1000


def test_an_interrupted_sweep_resumes_without_redoing_jobs(grid: Path, tmp_path: Path) -> None:
    spec = load_sweep(grid)
    out = tmp_path / "out"
    first = run_sweep(spec, out, workers=1, progress=False, stop_after=2)
    assert first.ran == 2 and not (out / "aggregate.csv").exists()
    done_before = read_log(out / "jobs.jsonl")
    assert len(done_before) == 2
    # A writer killed mid-line leaves a torn last line: it is ignored.
    with (out / "jobs.jsonl").open("a") as handle:
        handle.write('{"id": "torn')
    second = run_sweep(spec, out, workers=1, progress=False)
    assert second.skipped == 2 and second.ran == 2
    log = read_log(out / "jobs.jsonl")
    assert len(log) == 4
    for job_id, record in done_before.items():
        assert log[job_id] == record  # not redone
    assert len(_rows(out / "aggregate.csv")) == 4


def test_a_finished_sweep_run_again_redoes_nothing_and_rewrites_its_aggregate(
    grid: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    argv = ["sweep", str(grid), "--out", str(out), "--workers", "1", "--no-progress"]
    assert main(argv) == 0
    log, aggregate = (out / "jobs.jsonl").read_text(), (out / "aggregate.csv").read_text()
    (out / "aggregate.csv").unlink()
    capsys.readouterr()
    assert main(argv) == 0
    assert "0 jobs run (4 already done); 0 failed" in capsys.readouterr().out
    assert (out / "jobs.jsonl").read_text() == log
    assert (out / "aggregate.csv").read_text() == aggregate


def test_a_crashing_job_is_retried_once_reported_and_the_rest_complete(
    grid: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(CRASH_ENV, "1")
    out = tmp_path / "out"
    code = main(["sweep", str(grid), "--out", str(out), "--workers", "1", "--no-progress"])
    assert code == 1
    records = {
        r["index"]: r for r in map(json.loads, (out / "jobs.jsonl").read_text().splitlines())
    }
    assert records[1]["status"] == "crashed" and records[1]["attempts"] == 2
    assert [records[i]["status"] for i in (0, 2, 3)] == ["ok"] * 3
    rows = _rows(out / "aggregate.csv")
    assert [r["status"] for r in rows] == ["ok", "crashed", "ok", "ok"]


def _batched(grid: Path, worlds: int) -> Path:
    text = grid.read_text().replace(
        "[grid]", f'backend = "batch"\n\n[batch]\nworlds = {worlds}\n\n[grid]', 1
    )
    path = grid.with_name("batched.toml")
    path.write_text(text)
    return path


def test_a_batch_sweep_gives_the_classic_outputs_and_resumes(
    grid: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two chunks of two heads in lockstep: the first, then a resume for the second; the
    aggregate has the classic sweep's rows, columns and plots, and each job's error is
    the classic job's within the servo's noise."""
    classic = run_sweep(load_sweep(grid), tmp_path / "classic", progress=False)
    spec = load_sweep(_batched(grid, 2))
    assert spec.backend == "batch" and spec.batch.worlds == 2
    out = tmp_path / "batch"
    first = run_sweep(spec, out, progress=False, stop_after=2)
    assert first.ran == 2 and first.rendered is not None
    assert first.rendered["largest"] == 2  # both jobs' heads in lockstep
    assert main(["sweep", str(spec.path), "--out", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "batch back-end: lockstep heads through one OpenGL context" in printed
    assert "Warp" not in printed  # the back-end draws through OpenGL, whatever the device
    assert "2 jobs run (2 already done)" in printed
    rows, expected = _rows(out / "aggregate.csv"), _rows(tmp_path / "classic" / "aggregate.csv")
    assert list(rows[0]) == list(expected[0])
    assert [r["status"] for r in rows] == ["ok"] * 4
    for row, ref in zip(rows, expected, strict=True):
        assert row["head.baseline_m"] == ref["head.baseline_m"]
        # The servo's noise: both converge within ~0.1 px, about 0.05 % of depth here.
        assert abs(float(row["rms_error_pct_depth"]) - float(ref["rms_error_pct_depth"])) < 0.05
    assert {r["backend"] for r in read_log(out / "jobs.jsonl").values()} == {"batch"}
    assert (out / "error_vs_head_baseline_m.png").stat().st_size > 1000
    assert not classic.failed


def test_a_batch_sweep_runs_a_procedure_lockstep_lacks_the_classic_way_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = (DATA / "sweep_base.toml").read_text()
    (tmp_path / "model1.toml").write_text(
        base.replace('procedure = "model2"', 'procedure = "model1"')
    )
    sweep = tmp_path / "model1_sweep.toml"
    sweep.write_text(
        'description = "Model 1: not in lockstep"\nscenario = "model1.toml"\n'
        'backend = "batch"\n[batch]\nworlds = 2\n[grid]\n"head.baseline_m" = [0.12, 0.18]\n'
    )
    outcome = run_sweep(load_sweep(sweep), tmp_path / "out", progress=True)
    records = read_log(tmp_path / "out" / "jobs.jsonl").values()
    assert {r["status"] for r in records} == {"ok"}
    assert {r["backend"] for r in records} == {"classic"}
    assert {r["classic_because"] for r in records} == {"procedure 'model1' (lockstep runs model2)"}
    assert "classic path: procedure 'model1'" in capsys.readouterr().err
    assert not outcome.failed


def test_a_crashing_job_in_a_batch_takes_no_other_job_down(
    grid: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Job 1 kills its process: its batch fails whole (twice), then each of its jobs runs
    on its own; only job 1 is recorded as crashed."""
    monkeypatch.setenv(CRASH_ENV, "1")
    outcome = run_sweep(load_sweep(_batched(grid, 2)), tmp_path / "out", progress=False)
    status = {r["index"]: r["status"] for r in outcome.records.values()}
    assert status == {0: "ok", 1: "crashed", 2: "ok", 3: "ok"}
    attempts = {r["index"]: r["attempts"] for r in outcome.records.values()}
    assert attempts == {0: 3, 1: 4, 2: 1, 3: 1}


def test_a_batch_sweep_on_a_missing_device_is_refused_before_it_runs(
    grid: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from headsim.sim.batch import cuda_available

    out = tmp_path / "out"
    code = main(["sweep", str(_batched(grid, 2)), "--out", str(out), "--device", "cuda"])
    if cuda_available():
        assert code == 0
        return
    assert code == 2
    assert "Warp finds no CUDA device here; allowed: cpu" in capsys.readouterr().err
    assert not (out / "jobs.jsonl").exists()
    assert main(["sweep", str(grid), "--out", str(out), "--device", "cpu"]) == 2
    assert "allowed only with backend" in capsys.readouterr().err


#: A target 0.3 m ahead: a 0.9 m baseline needs an eye angle beyond the eyes' range for it.
NEAR_TARGET = """description = "one near marker; a wide baseline cannot fixate it"
seed = 0

[head]
preset = "ideal"

[experiment]
procedure = "model2"

[[scene.targets]]
name = "near"
position_head_m = [0.03, 0.01, 0.3]

[fast]
cam1.noise_std = 0.0
"""


def _refusing_sweep(tmp_path: Path, backend: str = "") -> Path:
    (tmp_path / "near.toml").write_text(NEAR_TARGET)
    path = tmp_path / f"refusing{backend}.toml"
    path.write_text(
        'description = "baseline: the second one puts the target out of reach"\n'
        'scenario = "near.toml"\nfast = true\n'
        + (f'backend = "{backend}"\n[batch]\nworlds = 2\n' if backend else "")
        + '[grid]\n"head.baseline_m" = [0.15, 0.9]\n'
    )
    return path


def test_a_job_its_scenario_refuses_is_that_jobs_failure_and_the_others_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    sweep = _refusing_sweep(tmp_path)
    code = main(["sweep", str(sweep), "--out", str(out), "--workers", "1", "--no-progress"])
    printed = capsys.readouterr()
    assert code == 1, printed.err  # a job failed; the sweep file was fine (not 2)
    records = {r["index"]: r for r in read_log(out / "jobs.jsonl").values()}
    assert records[0]["status"] == "ok" and records[0]["measurements_ok"] == 1
    refused = records[1]
    assert (refused["status"], refused["refusal"], refused["attempts"]) == (
        "refused",
        "eye_range",
        1,  # not retried: the same values are refused again
    )
    assert "needs an eye angle of" in refused["failure_reasons"][0]
    assert [r["status"] for r in _rows(out / "aggregate.csv")] == ["ok", "refused"]
    assert "job 1 refused: scenario refused: target at [0.030, 0.010, 0.300] m in H" in (
        printed.out
    )
    assert "1 failed" in printed.out


def test_a_refused_job_on_the_batch_back_end_is_its_failure_alone(tmp_path: Path) -> None:
    outcome = run_sweep(
        load_sweep(_refusing_sweep(tmp_path, "batch")), tmp_path / "out", progress=False
    )
    status = {r["index"]: (r["status"], r.get("refusal")) for r in outcome.records.values()}
    assert status == {0: ("ok", None), 1: ("refused", "eye_range")}
    assert len(outcome.failed) == 1
