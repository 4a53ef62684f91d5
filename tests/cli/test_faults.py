"""The exit-code contract, held by the real command line under injected faults.

Each test runs ``python -m headsim.cli`` in a subprocess, as a user would, and
checks the exit code (0 ok, 1 failed, 2 bad input, 3 environment, 130
interrupted), a one-line reason on stderr and no traceback, and that nothing
half-written (results.json, an empty output folder) is left behind.
"""

from __future__ import annotations

import ctypes.util
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

CLI = [sys.executable, "-m", "headsim.cli"]


def _env(**extra: str) -> dict[str, str]:
    env = {**os.environ, **extra}
    env.setdefault("MUJOCO_GL", "egl")
    return env


def headsim(
    *args: str,
    env: dict[str, str] | None = None,
    cwd: Path | None = None,
    file_size_limit: int | None = None,
    timeout: float = 300,
) -> subprocess.CompletedProcess[str]:
    """Run the real CLI; ``file_size_limit`` (bytes) is ``ulimit -f`` for the child."""

    def limit() -> None:
        if file_size_limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (file_size_limit, file_size_limit))

    return subprocess.run(
        [*CLI, *args],
        env=env or _env(),
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        preexec_fn=limit,
    )


def assert_one_line_error(result: subprocess.CompletedProcess[str], code: int, *needles: str):
    """Exit ``code``, no traceback, and one ``headsim: error:`` line containing ``needles``."""
    assert result.returncode == code, (result.returncode, result.stderr[-2000:])
    assert "Traceback" not in result.stderr, result.stderr
    errors = [line for line in result.stderr.splitlines() if line.startswith("headsim: error:")]
    assert len(errors) == 1, result.stderr
    for needle in needles:
        assert needle in errors[0], errors[0]
    return errors[0]


def read_only_dir(tmp_path: Path) -> Path:
    """An existing directory this process cannot write in (chmod; as root, where permission
    bits do not apply, /proc/sys: procfs takes no new files)."""
    if os.geteuid() == 0:  # root ignores permission bits: use a read-only file system
        path = Path("/proc/sys")
    else:
        path = tmp_path / "read-only"
        path.mkdir()
        path.chmod(0o555)
    assert path.is_dir()
    try:  # the premise: no file can be created there
        fd, name = tempfile.mkstemp(dir=path)
    except OSError:
        return path
    os.close(fd)
    os.unlink(name)
    raise AssertionError(f"{path} is writable: no read-only directory for this test")


# -- the contract is documented ---------------------------------------------------


def test_help_states_the_exit_codes_and_needs_no_gl() -> None:
    for args in (["--help"], ["run", "--help"], ["sweep", "--help"]):
        result = headsim(*args, env=_env(MUJOCO_GL="bogus"))
        assert result.returncode == 0, result.stderr
        text = " ".join(result.stdout.split())
        assert "1 a measurement or job failed" in text
        assert "3 the environment (no GL backend, output not writable, disk full" in text
        assert "130 interrupted" in text


def test_debug_shows_the_traceback_and_keeps_the_code(tmp_path: Path) -> None:
    plain = headsim("run", "no_such_scenario", "--out", str(tmp_path / "x"))
    assert_one_line_error(plain, 2, "no_such_scenario: no such scenario file")
    debug = headsim("run", "no_such_scenario", "--out", str(tmp_path / "x"), "--debug")
    assert debug.returncode == 2
    assert "Traceback (most recent call last)" in debug.stderr
    assert "ScenarioError" in debug.stderr


# -- GL backend -------------------------------------------------------------------


def test_a_bad_gl_value_is_an_environment_problem_before_anything_runs(tmp_path: Path) -> None:
    out = tmp_path / "out"
    for value, needle in (
        ("bogus", "MUJOCO_GL='bogus' is not a backend headsim can render with"),
        ("disable", "MUJOCO_GL=disable turns rendering off"),
    ):
        result = headsim("run", "quickstart", "--out", str(out), env=_env(MUJOCO_GL=value))
        line = assert_one_line_error(result, 3, needle)
        assert "apt-get install" in line
        assert not out.exists()
    # Commands that do not render work without GL.
    listing = headsim("list", env=_env(MUJOCO_GL="bogus"))
    assert listing.returncode == 0, listing.stderr
    assert "quickstart" in listing.stdout


def test_osmesa_runs_or_says_what_to_install(tmp_path: Path) -> None:
    result = headsim(
        "snapshot", "--out", str(tmp_path / "snap"), env=_env(MUJOCO_GL="osmesa"), timeout=120
    )
    if ctypes.util.find_library("OSMesa") is None:
        assert_one_line_error(result, 3, "libOSMesa is not installed", "apt-get install libosmesa6")
        assert not (tmp_path / "snap").exists()
    else:
        assert result.returncode == 0, result.stderr
        assert (tmp_path / "snap" / "cam1.png").is_file()


# -- outputs ----------------------------------------------------------------------


def test_a_read_only_output_folder_is_refused_before_the_run(tmp_path: Path) -> None:
    read_only = read_only_dir(tmp_path)
    result = headsim("run", "quickstart", "--out", str(read_only))
    assert_one_line_error(result, 3, f"--out: cannot write in {read_only}")
    rrd = headsim(
        "run", "quickstart", "--out", str(tmp_path / "out"), "--rrd", str(read_only / "x.rrd")
    )
    assert_one_line_error(rrd, 3, "--rrd: cannot write in")
    assert not (tmp_path / "out").exists()  # the folder it created is gone again
    # Refused before the run: no phase started (each phase prints a progress line).
    assert "headsim: calibration" not in result.stderr + rrd.stderr


def test_a_full_disk_mid_recording_names_the_file_and_leaves_no_results(tmp_path: Path) -> None:
    out = tmp_path / "out"
    rrd = out / "run.rrd"
    result = headsim(
        "run", "quickstart", "--fast", "--out", str(out), "--rrd", str(rrd),
        file_size_limit=100_000,
    )  # fmt: skip
    line = assert_one_line_error(result, 3, f"no space to write {rrd}", "ulimit -f")
    assert "100.0 kB" in line
    assert not (out / "results.json").exists()
    assert rrd.stat().st_size == 100_000  # what Rerun wrote before the limit stays
    assert not list(out.glob(".*.tmp"))


def test_a_full_disk_for_results_leaves_no_partial_file_and_no_folder(tmp_path: Path) -> None:
    out = tmp_path / "deep" / "out"
    result = headsim("run", "quickstart", "--fast", "--out", str(out), file_size_limit=2_000)
    assert_one_line_error(result, 3, f"no space to write {out / 'results.json'}", "needed")
    assert not (tmp_path / "deep").exists()


def test_no_space_on_the_device_itself_is_exit_3(tmp_path: Path) -> None:
    assert Path("/dev/full").exists()  # Linux: every write fails with ENOSPC
    result = headsim(
        "run", "quickstart", "--fast", "--out", str(tmp_path / "out"), "--rrd", "/dev/full"
    )
    assert_one_line_error(result, 3, "no space to write /dev/full")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [("sweep", "sweeps/focal.toml"), ("study", "--sweep", "depth")])
def test_workers_0_is_bad_input_and_creates_nothing(
    tmp_path: Path, command: tuple[str, ...]
) -> None:
    root = Path(__file__).resolve().parents[2]
    name, *rest = command
    argv = [str(root / a) if a.endswith(".toml") else a for a in rest]
    result = headsim(name, *argv, "--out", str(tmp_path / "out"), "--workers", "0")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert "argument --workers: 0 is not allowed (allowed: an integer >= 1)" in result.stderr
    assert not (tmp_path / "out").exists()


# -- interruption -----------------------------------------------------------------


def _interrupt(args: list[str], *, after_s: float | None = None, after_line: str | None = None):
    process = subprocess.Popen(
        [*CLI, *args], env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert process.stderr is not None
    if after_s is not None:
        time.sleep(after_s)
    else:
        assert after_line is not None
        seen = []
        for line in process.stderr:  # progress lines: stderr is not a terminal
            seen.append(line)
            if after_line in line:
                break
        else:
            raise AssertionError(f"never saw {after_line!r}: {seen}")
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    return process.returncode, stdout, stderr


@pytest.mark.parametrize("after_s", [0.15, 0.3, 0.6])
def test_interrupt_during_start_up_is_130_without_a_traceback(
    tmp_path: Path, after_s: float
) -> None:
    """Early (the commands still importing, inside main's guard) and later (numpy,
    mujoco and the scenario loading): one line, exit 130, no folder."""
    out = tmp_path / "out"
    code, _, stderr = _interrupt(["run", "quickstart", "--out", str(out)], after_s=after_s)
    assert code == 130, stderr
    assert "Traceback" not in stderr
    assert "interrupted" in stderr
    assert not out.exists()


def test_interrupt_mid_run_is_130_and_leaves_no_empty_folder(tmp_path: Path) -> None:
    out = tmp_path / "out"
    code, _, stderr = _interrupt(
        ["run", "quickstart", "--fast", "--out", str(out)], after_line="headsim: calibration:"
    )
    assert code == 130, stderr
    assert "Traceback" not in stderr
    assert "interrupted: nothing written" in stderr
    assert not out.exists()


@pytest.mark.parametrize("args", [("list",), ("bench", "--list")])
def test_a_reader_that_stops_reading_ends_the_command_quietly(args: tuple[str, ...]) -> None:
    """``headsim list | head -1``: the reader has gone before the listing is written; the
    command stops with exit 0 and prints nothing, rather than an error about the pipe."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        proc = subprocess.run(
            [*CLI, *args], stdout=write_end, stderr=subprocess.PIPE, env=_env(), timeout=120
        )
    finally:
        os.close(write_end)
    assert (proc.returncode, proc.stderr.decode()) == (0, "")
