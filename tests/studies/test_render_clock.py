"""The render clock (studies/render_clock.py): it times real renders and counts CPU time."""

from __future__ import annotations

from headsim.studies.render_clock import CLOCK_RENDERS, RenderClock, cpu_s


def test_cpu_time_only_grows() -> None:
    before = cpu_s()
    total = sum(i * i for i in range(200_000))  # some work of this process
    assert total > 0 and cpu_s() > before


def test_the_clock_keeps_every_renders_time_and_returns_the_median() -> None:
    clock = RenderClock()
    try:
        first = clock.sample(3)
        second = clock.sample(2)
        assert len(clock.times_s) == len(clock.cpu_s) == 5
        assert first == sorted(clock.times_s[:3])[1]
        assert second == sum(clock.times_s[3:]) / 2
        assert all(t > 0 for t in clock.times_s)
    finally:
        clock.close()
    assert CLOCK_RENDERS[0] > CLOCK_RENDERS[1] > 0
