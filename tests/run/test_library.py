"""headsim as a library: ``headsim.load_scenario``, ``headsim.run``, typed rows and the table."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pandas
import pytest

import headsim
from headsim.cli import main
from headsim.runs.library import dotted_overrides
from headsim.runs.outcomes import MeasurementRow
from headsim.runs.result import RunResult


def plain_python(code: str, cwd: Path) -> str:
    """``code`` run by a plain ``python -c`` (no pytest, no conftest): its stdout."""
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_import_headsim_loads_neither_numpy_nor_mujoco(tmp_path: Path) -> None:
    out = plain_python(
        "import sys, headsim\n"
        "print(sorted(m for m in ('numpy', 'mujoco', 'cv2', 'headsim.runs.runner') if m in sys.modules))",
        tmp_path,
    )
    assert out.strip() == "[]"


def test_run_quickstart_in_a_plain_python_session(tmp_path: Path) -> None:
    out = plain_python(
        "import headsim\n"
        "r = headsim.run('quickstart', seed=1)\n"
        "rows = r.measurements\n"
        "print(type(r).__name__, r.ok, len(rows), {type(m).__name__ for m in rows})\n"
        "print(all(m.error_pct_of_depth < 2.0 for m in rows))",
        tmp_path,
    )
    assert out.splitlines() == ["RunResult True 5 {'MeasurementRow'}", "True"]
    assert list(tmp_path.iterdir()) == []  # nothing written unless asked


@pytest.fixture(scope="module")
def fast_run() -> RunResult:
    return headsim.run("quickstart", seed=1, fast=True)


def test_the_same_seed_gives_the_same_measurements(fast_run: RunResult) -> None:
    again = headsim.run(headsim.load_scenario("quickstart", seed=1, fast=True))
    assert again.measurements == fast_run.measurements
    other = headsim.run("quickstart", seed=2, fast=True)
    assert other.measurements != fast_run.measurements


def test_rows_are_typed_and_frozen(fast_run: RunResult) -> None:
    rows = fast_run.measurements
    assert [r.name for r in rows] == [r.measurement.name for r in fast_run.records]
    row = rows[0]
    assert isinstance(row, MeasurementRow) and row.ok and row.status == "ok"
    error = math.dist(row.estimate_head_m, row.truth_head_m)
    assert row.error_m == pytest.approx(error)
    assert row.error_pct_of_depth == pytest.approx(100.0 * error / row.truth_head_m[2])
    with pytest.raises(AttributeError):
        row.name = "other"  # type: ignore[misc]


def test_pandas_takes_the_table_as_it_is(fast_run: RunResult) -> None:
    table = fast_run.table()
    assert {len(column) for column in table.values()} == {len(fast_run.measurements)}
    frame = pandas.DataFrame(table)
    assert list(frame["name"]) == [r.name for r in fast_run.measurements]
    assert list(frame["truth_world_z_m"]) == [r.truth_world_m[2] for r in fast_run.measurements]
    assert frame["error_pct_of_depth"].dtype == float


def test_out_and_record_write_what_the_command_line_writes(tmp_path: Path) -> None:
    cli = tmp_path / "cli"
    assert main(["--quiet", "run", "quickstart", "--fast", "--out", str(cli)]) == 0
    lib, rrd = tmp_path / "lib", tmp_path / "lib" / "run.rrd"
    headsim.run("quickstart", fast=True, out=lib, record=rrd)
    for name in ("results.json", "summary.txt"):
        assert (lib / name).read_bytes() == (cli / name).read_bytes(), name
    assert json.loads((lib / "results.json").read_text())["status"] == "ok"
    assert rrd.stat().st_size > 10_000


def test_overrides_as_tables_and_dotted_keys() -> None:
    assert dotted_overrides({"cam1": {"kx": 7.0}, "scene.count": 2}) == {
        "cam1.kx": 7.0,
        "scene.count": 2,
    }
    assert dotted_overrides({"cam1": {}}) == {}  # merging no key changes nothing
    by_table = headsim.load_scenario("quickstart", fast=True, cam1={"noise_std": 3.0})
    by_key = headsim.load_scenario("quickstart", fast=True, overrides={"cam1.noise_std": 3.0})
    assert by_table == by_key
    assert by_table.settings.cameras[0].noise_std == 3.0
    # An override wins over the file's [fast] value for the same field.
    more = headsim.load_scenario("quickstart", fast=True, scene={"random_targets": {"count": 2}})
    assert len(more.scene.targets) == 4


@pytest.mark.parametrize(
    ("overrides", "field", "allowed"),
    [
        ({"cam1": {"focal": 700.0}}, "cam1.focal", "noise_std"),
        ({"cam1.noise_std": -1.0}, "cam1.noise_std", ">= 0"),
        ({"cam1..kx": 1.0}, "cam1..kx", "dotted names"),
    ],
)
def test_a_bad_override_names_its_field(overrides: dict, field: str, allowed: str) -> None:
    with pytest.raises(headsim.ScenarioError) as caught:
        headsim.load_scenario("quickstart", overrides=overrides)
    assert caught.value.field == field
    assert allowed in str(caught.value) and "\n" not in str(caught.value)


def test_a_loaded_scenario_keeps_its_seed() -> None:
    scenario = headsim.load_scenario("quickstart", fast=True)
    with pytest.raises(headsim.ScenarioError, match="seed: the scenario was loaded with seed = 0"):
        headsim.run(scenario, seed=3)


def test_headsim_run_is_the_function_and_the_runs_package_is_apart() -> None:
    import headsim.runs.runner
    from headsim.runs.library import run

    assert headsim.run is run and headsim.runs.runner.run_scenario is not None
    assert headsim.HeadSim.__name__ == "HeadSim" and "load_scenario" in dir(headsim)


def test_a_result_in_a_notebook_is_short_and_its_summary_is_summary_txt(
    fast_run: RunResult, tmp_path: Path
) -> None:
    from headsim.runs.accuracy import summarise

    rms = summarise(fast_run.records).error_pct_of_depth_rms
    n = len(fast_run.records)
    assert repr(fast_run) == (
        f"<RunResult quickstart (fast), seed 1, model2: {n} of {n} measured; "
        f"3-D error RMS {rms:.3f} % of depth; ok>"
    )
    html = fast_run._repr_html_()
    assert html.startswith("<table>") and html.endswith("</table>") and len(html) < 2000
    assert f"<td style='text-align:left'>{rms:.3f}</td>" in html
    assert "&gt;= 1 m" in html  # escaped
    assert (
        main(["--quiet", "run", "quickstart", "--fast", "--seed", "1", "--out", str(tmp_path)]) == 0
    )
    assert fast_run.summary() + "\n" == (tmp_path / "summary.txt").read_text()


def test_plot_draws_each_measured_error_at_its_depth_under_agg(fast_run: RunResult) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = fast_run.plot()
    assert isinstance(figure, Figure)
    FigureCanvasAgg(figure).draw()  # renders without a display
    (axes,) = figure.axes
    ok = [row for row in fast_run.measurements if row.status == "ok"]
    points = sorted(
        (float(x), float(y))
        for line in axes.get_lines()
        for x, y in zip(*line.get_data(), strict=True)
    )
    assert points == sorted((row.depth_m, row.error_pct_of_depth) for row in ok)
    assert axes.get_xlabel() == "true depth, m" and axes.get_ylabel() == "3-D error, % of depth"


def test_a_type_checker_sees_headsim_run_as_the_function(tmp_path: Path) -> None:
    """mypy on a user's script: ``headsim.run(...)`` is a call returning a RunResult, not
    "Module not callable"."""
    from mypy import api

    script = tmp_path / "user.py"
    script.write_text('import headsim\n\nreveal_type(headsim.run("quickstart", fast=True))\n')
    out, err, status = api.run(
        [str(script), "--cache-dir", str(tmp_path / "cache"), "--follow-imports", "silent"]
    )
    assert status == 0 and "Module not callable" not in out, out + err
    assert 'Revealed type is "headsim.runs.result.RunResult"' in out, out
