"""Timing 640x480 renders in this process, the unit of ``headsim reproduce``'s wall and
CPU ratios, s."""

from __future__ import annotations

import resource
import statistics
import time

from headsim.sim.settings import HeadSettings


def cpu_s() -> float:
    """CPU time, user and system, of this process and its children that ended, s."""
    own, children = (
        resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
    )
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


class RenderClock:
    """Times renders of the default scene in this process (by default the ideal head's,
    640x480), while no worker of the run works: once they started and wait, idle, for
    their first jobs, and a few after they ended.  The unit is the quieter of the two
    medians (the machine's other load only adds time); both are reported."""

    def __init__(self, settings: HeadSettings | None = None) -> None:
        from headsim.sim.simulator import for_settings

        self._sim = for_settings(settings or HeadSettings())
        self._sim.move(eye=0.05)
        for camera in (1, 2):
            self._sim.render(camera)
        self.times_s: list[float] = []
        #: CPU time of each render (all of this process's threads: llvmpipe's too), s.
        self.cpu_s: list[float] = []

    def sample(self, renders: int) -> float:
        """Time ``renders`` more renders; their median wall time, s."""
        times = []
        for _ in range(renders):
            start, cpu = time.perf_counter(), time.process_time()
            self._sim.render(1 + len(self.times_s) % 2)
            times.append(time.perf_counter() - start)
            self.cpu_s.append(time.process_time() - cpu)
        self.times_s += times
        return statistics.median(times)

    def close(self) -> None:
        self._sim.close()


#: Renders timed before the workers' first jobs and after they end (the unit: the quieter median).
CLOCK_RENDERS = (7, 5)
