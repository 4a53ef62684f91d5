"""Every benchmark is a case of ``headsim bench``: the cases file in step with benchmarks/,
and the command's listing, case choice and refusals."""

from __future__ import annotations

import pytest

from headsim.cli import main
from headsim.studies.bench import PART_RUNS, PARTS
from headsim.studies.bench_cases import CASES, KINDS, _load, of_kind
from headsim.studies.checks import BENCH_DIR

#: Scripts in benchmarks/ that are not benchmarks (none today).
NOT_CASES: set[str] = set()


def test_every_benchmark_script_is_a_case_and_every_case_script_exists() -> None:
    scripts = {p.name for p in BENCH_DIR.glob("*.py")} - NOT_CASES
    assert scripts == {c.script for c in CASES.values() if c.script is not None}
    assert all(c.kind in KINDS for c in CASES.values())
    assert all((c.script is None) == (c.kind == "regress") for c in CASES.values())


def test_each_regression_case_has_its_part_and_each_part_its_case() -> None:
    assert tuple(c.name for c in of_kind("regress")) == PARTS
    assert set(PART_RUNS) == set(PARTS)
    assert {"ideal", "paper", "realistic", "scenarios", "speed"} <= set(PARTS)


def test_a_cases_file_with_an_unknown_table_is_refused(tmp_path) -> None:
    path = tmp_path / "cases.toml"
    path.write_text('[regress]\nideal = "x"\n[slow]\nsome = "some.py"\n')
    with pytest.raises(ValueError, match=r"unknown tables \['slow'\]"):
        _load(path)


def test_list_names_every_case_with_its_scripts_first_docstring_line(capsys) -> None:
    assert main(["bench", "--list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == list(CASES)
    (reach,) = [line for line in lines if line.startswith("reach_and_zoom ")]
    assert "long" in reach and "Every target the reach check accepts" in reach


def test_a_figures_case_runs_its_script_with_the_arguments_after_the_dashes(capfd) -> None:
    assert main(["bench", "--case", "estimators_throughput", "--", "--help"]) == 0
    out = capfd.readouterr().out
    assert out.startswith("== estimators_throughput: Throughput of Model 2")
    assert "usage: estimators_throughput.py" in out


@pytest.mark.parametrize(
    ("argv", "why"),
    [
        (["--case", "no_such_case"], "no bench case named 'no_such_case'"),
        (["--all", "--", "--help"], "go to one figures case"),
        (["--case", "ideal", "--update-baseline"], "needs the whole regression suite"),
    ],
)
def test_bench_refuses_what_it_cannot_run(argv: list[str], why: str, capsys) -> None:
    assert main(["bench", *argv]) == 2
    assert why in capsys.readouterr().err


def test_a_script_ended_by_a_signal_is_a_failure_not_a_success(tmp_path, capfd) -> None:
    from headsim.studies.bench_cases import BenchCase, run_script

    script = tmp_path / "crash.py"
    script.write_text(
        '"""Dies of SIGKILL."""\nimport os, signal\nos.kill(os.getpid(), signal.SIGKILL)\n'
    )
    # An absolute script path stands for itself, outside benchmarks/.
    assert run_script(BenchCase("crash", "figures", str(script)), []) == 1
    assert "== crash: Dies of SIGKILL." in capfd.readouterr().out
