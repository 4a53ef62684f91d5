"""The exit-code contract: each exception's code and one line, and guarded's behaviour."""

from __future__ import annotations

import errno
import io
import signal

import pytest

from headsim.errors import (
    EXIT_CODES_HELP,
    BadInput,
    DiskFull,
    EnvironmentProblem,
    ExitCode,
    JobFailed,
    OutputNotWritable,
    clear_interrupted,
    exit_code_for,
    guarded,
    interrupt_handler,
    interrupted,
    note_interrupt,
    raise_if_interrupted,
)


@pytest.fixture(autouse=True)
def _no_interrupt_left() -> None:
    clear_interrupted()
    yield
    clear_interrupted()


@pytest.mark.parametrize(
    ("error", "code", "line"),
    [
        (JobFailed("job 3 failed"), ExitCode.FAILED, "job 3 failed"),
        (BadInput("--out: x is a file"), ExitCode.BAD_INPUT, "--out: x is a file"),
        (EnvironmentProblem("no EGL"), ExitCode.ENVIRONMENT, "no EGL"),
        (OutputNotWritable("cannot write y"), ExitCode.ENVIRONMENT, "cannot write y"),
        (DiskFull("no space to write z"), ExitCode.ENVIRONMENT, "no space to write z"),
        (
            OSError(errno.ENOSPC, "No space left on device", "/data/r.json"),
            ExitCode.ENVIRONMENT,
            "no space to write /data/r.json: No space left on device (free some space",
        ),
        (
            OSError(errno.EACCES, "Permission denied", "/etc/x"),
            ExitCode.ENVIRONMENT,
            "cannot use /etc/x: Permission denied",
        ),
        (MemoryError(), ExitCode.ENVIRONMENT, "out of memory"),
        (
            ImportError("No module named 'cv2'", name="cv2"),
            ExitCode.ENVIRONMENT,
            "a dependency is missing: cv2",
        ),
        (RecursionError(), ExitCode.BAD_INPUT, "input nested too deeply to process"),
        (
            ValueError("bad"),
            ExitCode.FAILED,
            "internal error: ValueError: bad (run with --debug for the traceback)",
        ),
        (KeyboardInterrupt(), ExitCode.INTERRUPTED, "interrupted"),
    ],
)
def test_each_exception_has_its_code_and_one_line(
    error: BaseException, code: ExitCode, line: str
) -> None:
    got_code, message = exit_code_for(error)
    assert got_code == code
    assert line in message
    assert "\n" not in message


def test_an_interrupt_noted_by_the_handler_makes_any_error_130() -> None:
    with pytest.raises(KeyboardInterrupt):
        interrupt_handler(signal.SIGTERM, None)
    assert interrupted()
    # An interrupt inside a C extension surfaces as another exception: still 130.
    assert exit_code_for(ImportError("initialization failed")) == (
        ExitCode.INTERRUPTED,
        "interrupted",
    )
    clear_interrupted()
    assert not interrupted()
    assert exit_code_for(ImportError("x"))[0] == ExitCode.ENVIRONMENT


def test_guarded_returns_the_code_and_writes_one_line() -> None:
    stream = io.StringIO()
    assert guarded(lambda: 0, stream=stream) == 0
    assert stream.getvalue() == ""

    def bad() -> int:
        raise BadInput("scenario.toml: camera.kx: -1 is not allowed (allowed: > 0)")

    assert guarded(bad, stream=stream) == 2
    assert stream.getvalue() == (
        "headsim: error: scenario.toml: camera.kx: -1 is not allowed (allowed: > 0)\n"
    )


def test_guarded_with_debug_adds_the_traceback_and_interrupts_are_not_errors() -> None:
    stream = io.StringIO()

    def broken() -> int:
        return {}["missing"]

    assert guarded(broken, debug=True, stream=stream) == 1
    text = stream.getvalue()
    assert text.startswith("Traceback (most recent call last):")
    assert text.splitlines()[-1] == (
        "headsim: error: internal error: KeyError: 'missing' (run with --debug for the traceback)"
    )

    def stopped() -> int:
        raise KeyboardInterrupt

    stream = io.StringIO()
    assert guarded(stopped, stream=stream) == 130
    assert stream.getvalue() == "headsim: interrupted\n"


def test_usage_errors_pass_through_as_systemexit() -> None:
    def usage() -> int:
        raise SystemExit(2)

    with pytest.raises(SystemExit):
        guarded(usage, stream=io.StringIO())


def test_the_help_text_states_every_code() -> None:
    for code in ExitCode:
        assert f"{int(code)} " in EXIT_CODES_HELP


def test_an_interrupt_swallowed_on_the_way_still_exits_130() -> None:
    # The body ran on to the end (Python ignored the KeyboardInterrupt where it landed).
    stream = io.StringIO()

    def body() -> int:
        note_interrupt()
        return 0

    try:
        assert guarded(body, stream=stream) == 130
        assert stream.getvalue() == "headsim: interrupted\n"
        with pytest.raises(KeyboardInterrupt):
            raise_if_interrupted()
    finally:
        clear_interrupted()
    raise_if_interrupted()  # nothing noted: nothing raised
