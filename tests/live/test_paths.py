"""Target paths (live/paths.py): exact positions in time, visibility windows, checked fields."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.live import Jump, RandomWalk, Sinusoid, Static, Throw, Visibility, Waypoints
from headsim.live.paths import GRAVITY
from headsim.sim.settings import SettingsError


def test_waypoints_move_at_each_legs_speed_then_stay() -> None:
    # Legs of 0.3 m at 0.1 m/s (3 s) and 0.4 m at 0.2 m/s (2 s).
    path = Waypoints(((0.0, 0.0, 0.0), (0.3, 0.0, 0.0), (0.3, 0.4, 0.0)), (0.1, 0.2))
    assert path.duration_s == pytest.approx(5.0)
    assert path.max_speed_m_s == 0.2
    np.testing.assert_allclose(path.position(-1.0), [0.0, 0.0, 0.0])
    np.testing.assert_allclose(path.position(1.5), [0.15, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(path.position(3.0), [0.3, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(path.position(4.0), [0.3, 0.2, 0.0], atol=1e-12)
    np.testing.assert_allclose(path.position(99.0), [0.3, 0.4, 0.0])


def test_sinusoid_and_throw_are_their_closed_forms() -> None:
    wave = Sinusoid((0.0, 1.0, 0.2), (0.1, 0.0, 0.05), 0.5, (0.0, 0.0, math.pi / 2))
    # At t = 0.5 s the phase is pi/2: x at its crest, z (a quarter ahead) back at the centre.
    np.testing.assert_allclose(wave.position(0.5), [0.1, 1.0, 0.2], atol=1e-12)
    assert wave.max_speed_m_s == pytest.approx(math.pi * math.hypot(0.1, 0.05))
    throw = Throw((0.0, 1.0, 0.0), (0.5, 0.0, 3.0))
    np.testing.assert_allclose(throw.position(-1.0), [0.0, 1.0, 0.0])
    np.testing.assert_allclose(throw.position(2.0), [1.0, 1.0, 6.0 - 2.0 * GRAVITY], atol=1e-12)


def test_static_and_jump_hold_their_points_and_jump_at_the_instant() -> None:
    static = Static((0.1, 0.7, 0.2))
    np.testing.assert_array_equal(static.position(3.0), [0.1, 0.7, 0.2])
    assert static.max_speed_m_s == 0.0
    jump = Jump((0.0, 0.8, 0.2), (0.1, 0.8, 0.3), 0.4)
    np.testing.assert_array_equal(jump.position(0.39), [0.0, 0.8, 0.2])
    np.testing.assert_array_equal(jump.position(0.4), [0.1, 0.8, 0.3])


def test_visibility_windows_are_half_open_and_empty_means_always() -> None:
    always = Visibility()
    assert always.visible(-5.0) and always.visible(1e9)
    windows = Visibility(((0.0, 0.3), (0.5, 2.0)))
    assert [windows.visible(t) for t in (0.0, 0.29, 0.3, 0.4, 0.5, 1.99, 2.0)] == [
        True,
        True,
        False,
        False,
        True,
        True,
        False,
    ]


def test_random_walk_follows_its_seed_keeps_its_speed_and_its_box() -> None:
    start = (0.0, 0.8, 0.3)
    walk = RandomWalk(start, max_speed_m_s=0.3, duration_s=2.0, seed=3)
    same = RandomWalk(start, max_speed_m_s=0.3, duration_s=2.0, seed=3)
    other = RandomWalk(start, max_speed_m_s=0.3, duration_s=2.0, seed=4)
    times = np.arange(0.0, 2.0 + 1e-9, walk.step_s)
    points = np.array([walk.position(t) for t in times])
    np.testing.assert_array_equal(points, [same.position(t) for t in times])
    assert not np.allclose(points[-1], other.position(2.0))
    np.testing.assert_array_equal(points[0], start)
    # Query order does not matter, and the walk stays after its end.
    np.testing.assert_array_equal(walk.position(1.234), same.position(1.234))
    np.testing.assert_array_equal(walk.position(5.0), walk.position(2.0))
    speeds = np.linalg.norm(np.diff(points, axis=0), axis=1) / walk.step_s
    assert speeds.max() <= 0.3 + 1e-9 and speeds.max() > 0.1
    assert np.all(np.abs(points - start) <= np.asarray(walk.box_half_m) + 1e-12)


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: Waypoints(((0, 0, 0),), ()), "at least 2 points"),
        (lambda: Waypoints(((0, 0, 0), (1, 0, math.nan)), (1.0,)), r"points\[1\]"),
        (lambda: Sinusoid((0, 0, 0), (0.1, 0, 0), 0.0), "frequency_hz"),
        (lambda: RandomWalk((0, 0, 0), 0.3, -1.0), "duration_s"),
        (lambda: Throw((0, 0), (0, 0, 0)), "start"),
        (lambda: Static((0, 0, math.inf)), "point"),
        (lambda: Jump((0, 0, 0), (1, 0, 0), -0.1), "time_s"),
        (lambda: Visibility(((0.5, 0.2),)), "appear"),
    ],
)
def test_bad_paths_are_refused_with_the_field_named(make, field: str) -> None:
    with pytest.raises(SettingsError, match=field):
        make()
