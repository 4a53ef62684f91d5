"""Progress on stderr that reads well everywhere.

On a terminal the commands draw a one-line bar that redraws itself
(``runner.Progress``).  Elsewhere (CI logs, pipes, files) a carriage return
runs every update together on one line, so there they print plain lines: one
per phase or job, with counts and the estimated time left, and at most one
per ``interval_s`` in between.  ``--quiet`` turns both off.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any, TextIO

from headsim.run.runner import Observer


def is_terminal(stream: TextIO) -> bool:
    """Whether ``stream`` is an interactive terminal (a bar may redraw itself there)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def time_left(done: int, total: int, elapsed_s: float) -> str:
    """``"about 1:05 left"`` from the rate so far; ``"time left unknown"`` before the first."""
    if done >= total:
        return "done"
    if done <= 0 or elapsed_s <= 0:
        return "time left unknown"
    seconds = round((total - done) * elapsed_s / done)
    return f"about {seconds // 60}:{seconds % 60:02d} left"


class LineProgress(Observer):
    """A run's progress as plain lines: at each phase, then every ``interval_s`` and at the end."""

    def __init__(
        self,
        total: int,
        stream: TextIO,
        *,
        unit: str = "fixations",
        interval_s: float = 10.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.total = max(int(total), 1)
        self.stream = stream
        self.unit = unit
        self.interval_s = interval_s
        self.clock = clock
        self.start = clock()
        self.done = 0
        self.phase_name = "start"
        self._printed_at = -math.inf

    def line(self) -> str:
        """e.g. ``headsim: measurement: 12/48 fixations, 3.1/s, about 0:11 left``."""
        elapsed = max(self.clock() - self.start, 1e-9)
        done = min(self.done, self.total)
        return (
            f"headsim: {self.phase_name}: {done}/{self.total} {self.unit}, "
            f"{done / elapsed:.1f}/s, {time_left(done, self.total, elapsed)}"
        )

    def _print(self) -> None:
        self._printed_at = self.clock()
        print(self.line(), file=self.stream, flush=True)

    def phase(self, name: str, sim: Any, knowledge: Any, truth: Any) -> None:
        self.phase_name = name
        self._print()

    def step(self, step: int, label: str) -> None:
        self.done = step
        if self.clock() - self._printed_at >= self.interval_s:
            self._print()

    def finished(self, result: Any) -> None:
        self.done, self.phase_name = self.total, "finished"
        elapsed = self.clock() - self.start
        print(
            f"headsim: finished: {self.total} {self.unit} in {elapsed:.1f} s",
            file=self.stream,
            flush=True,
        )
