"""Progress on stderr, one way for every command: a tqdm bar on a terminal, plain lines elsewhere.

- :class:`Counter`: ``done`` of ``total`` things (fixations, ball positions,
  sweep jobs).  On a terminal a tqdm bar redraws itself with the count, the
  rate and the time left; elsewhere (CI logs, pipes, files), where a carriage
  return runs every update together on one line, it prints plain lines: one
  at each phase, at most one per ``interval_s`` in between (or one per item),
  and one at the end.
- :class:`RunProgress`: a :class:`Counter` of a run's fixations, subscribed
  to the run's events (:mod:`headsim.runs.events`).
- :class:`Status`: a command's phase messages (``headsim study``, ``bench``,
  ``reproduce``), each a line with the seconds since the start; a transient
  status is one redrawn tqdm line on a terminal instead.

``--quiet`` (and ``--no-progress``) turn all of them off: the commands then
build none.  tqdm is imported only when a bar is drawn, so ``headsim --help``
stays fast.
"""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TextIO

from headsim.active.events import FixationStarted, PhaseStarted
from headsim.errors import printable
from headsim.runs.events import RunFinished, Stamp

if TYPE_CHECKING:
    from tqdm import tqdm


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


def _columns(stream: TextIO) -> int:
    """The terminal's width in characters; 0 where it reports none (some pseudo-terminals)."""
    try:
        return os.get_terminal_size(stream.fileno()).columns
    except (AttributeError, OSError, ValueError):
        return 0


def _bar(stream: TextIO, **options: Any) -> tqdm[Any]:
    """A tqdm bar on ``stream``, as wide as the terminal (80 x 24 where it reports no size)."""
    from tqdm import tqdm

    if _columns(stream) > 0:
        return tqdm(file=stream, dynamic_ncols=True, **options)
    return tqdm(file=stream, ncols=80, nrows=24, **options)


class Counter:
    """``done`` of ``total`` ``unit`` on ``stream``: a tqdm bar on a terminal, else plain lines.

    A plain line reads ``headsim: measurement: 12/48 fixations, 3.1/s, about
    0:11 left`` (``name``, the phase if any, the count, the rate per second or,
    with ``per_minute``, per minute, the time left) and, at :meth:`close`,
    ``headsim: finished: 48 fixations in 15.2 s``.  ``interval_s``: at most one
    line per that many seconds between phases (0: one per update).
    ``notes_in_lines``: the notes of :meth:`update` go into the plain lines too (else
    only onto the bar).  ``terminal``: draw the bar (default: whether ``stream`` is a terminal).
    """

    def __init__(
        self,
        total: int,
        *,
        unit: str,
        name: str = "headsim",
        stream: TextIO | None = None,
        interval_s: float = 10.0,
        per_minute: bool = False,
        notes_in_lines: bool = False,
        terminal: bool | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.total = max(int(total), 1)
        self.unit = unit
        self.name = name
        self.stream = sys.stderr if stream is None else stream
        self.interval_s = interval_s
        self.per_minute = per_minute
        self.notes_in_lines = notes_in_lines
        self.clock = clock
        self.start = clock()
        self.done = 0
        self.phase_name = ""
        self.note = ""
        self._printed_at = -math.inf
        self._bar: tqdm[Any] | None = None
        if is_terminal(self.stream) if terminal is None else terminal:
            self._bar = _bar(self.stream, total=self.total, unit=f" {unit}", mininterval=0.25)

    def line(self) -> str:
        """The plain line as it stands, e.g. ``headsim: measurement: 12/48 fixations, 3.1/s, ...``."""
        elapsed = max(self.clock() - self.start, 1e-9)
        done = min(self.done, self.total)
        rate = f"{60 * done / elapsed:.1f}/min" if self.per_minute else f"{done / elapsed:.1f}/s"
        phase = f"{self.phase_name}: " if self.phase_name else ""
        note = f" {self.note}" if self.note and self.notes_in_lines else ""
        return (
            f"{self.name}: {phase}{done}/{self.total} {self.unit}{note}, "
            f"{rate}, {time_left(done, self.total, elapsed)}"
        )

    def _print(self, text: str) -> None:
        self._printed_at = self.clock()
        print(text, file=self.stream, flush=True)

    def phase(self, name: str) -> None:
        """A new phase begins: a line in a log, the bar's description on a terminal."""
        self.phase_name = name = printable(name)
        if self._bar is not None:
            self._bar.set_description_str(name)
        else:
            self._print(self.line())

    def update(self, done: int | None = None, note: str = "") -> None:
        """``done`` so far (default: one more); ``note``: what it was (the bar's postfix)."""
        done = self.done + 1 if done is None else done
        self.done, self.note = done, printable(note)
        if self._bar is not None:
            self._bar.set_postfix_str(self.note, refresh=False)
            self._bar.update(min(done, self.total) - self._bar.n)
        elif self.clock() - self._printed_at >= self.interval_s:
            self._print(self.line())

    def close(self, done: int | None = None) -> None:
        """The end, ``done`` (default: as counted) of ``total``: the bar left on screen, or
        the ``finished`` line."""
        self.done, self.note = self.done if done is None else done, ""
        if self._bar is not None:
            self._bar.set_postfix_str("", refresh=False)
            self._bar.update(min(self.done, self.total) - self._bar.n)
            self._bar.close()
            self._bar = None
            return
        elapsed = self.clock() - self.start
        self._print(f"{self.name}: finished: {self.done} {self.unit} in {elapsed:.1f} s")


class RunProgress:
    """A run's fixations as a :class:`Counter`, following the run's events (a
    :class:`headsim.runs.events.Subscriber`): a line, or the bar's title, at each phase."""

    def __init__(self, counter: Counter) -> None:
        self.counter = counter

    def notify(self, event: object, at: Stamp) -> None:
        if isinstance(event, PhaseStarted):
            # Every fixation begun before a phase has ended (``at.step`` is the last one's).
            self.counter.done = max(self.counter.done, at.step + 1)
            self.counter.phase(event.name)
        elif isinstance(event, FixationStarted):
            self.counter.update(at.step, event.label)
        elif isinstance(event, RunFinished):
            self.counter.close(self.counter.total)


class Status:
    """A command's phase messages on ``stream``, each with the seconds since the start.

    ``headsim bench: [   12.3 s] chessboard``, one line each; with ``transient``
    on a terminal one tqdm line redrawn with each message and the time so far,
    cleared by :meth:`close` (the next message draws a new one).  Call it with
    each message.  ``terminal``: redraw (default: whether ``stream`` is a terminal).
    """

    def __init__(
        self,
        name: str,
        *,
        stream: TextIO | None = None,
        transient: bool = False,
        terminal: bool | None = None,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        self.name = name
        self.stream = sys.stderr if stream is None else stream
        self.clock = clock
        self.start = clock()
        self.redraw = transient and (is_terminal(self.stream) if terminal is None else terminal)
        self._bar: tqdm[Any] | None = None

    def __call__(self, message: str) -> None:
        if self.redraw:
            if self._bar is None:
                self._bar = _bar(
                    self.stream,
                    total=None,
                    leave=False,
                    desc=message,
                    bar_format=f"{self.name}: [{{elapsed}}] {{desc}}",
                )
            else:
                self._bar.set_description_str(message)
            return
        elapsed = self.clock() - self.start
        print(f"{self.name}: [{elapsed:7.1f} s] {message}", file=self.stream, flush=True)

    def close(self) -> None:
        """Clear the transient line (plain lines need no end)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None


#: A progress callback: takes one line of news.
Progress = Callable[[str], None]


def quiet(_: str) -> None:
    """A progress callback that says nothing (``--quiet``)."""
