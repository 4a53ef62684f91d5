"""Target paths in the world frame (m, s): waypoints, sinusoid, random walk, throw.

A path is a pure function of time, ``position(t)`` (world, m), so a live run is
deterministic and ground truth at any instant (an image's exposure, a physics
step) is exact.  ``visible(t)`` says whether the target is in the scene at
``t``: outside its visibility windows a target is parked out of sight.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from headsim.sim.settings import SettingsError

#: Gravity, m/s^2, along world -z.
GRAVITY = 9.81


def _vector(name: str, value: object) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise SettingsError(f"{name} must be 3 finite numbers (x, y, z), got {value!r}")
    return array


@dataclass(frozen=True)
class Visibility:
    """Windows ``[(appear_s, disappear_s), ...]`` in which the target is present; empty: always."""

    windows: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        for start, end in self.windows:
            if not (math.isfinite(start) and math.isfinite(end) and end > start):
                raise SettingsError(
                    f"visibility windows must be (appear_s, disappear_s) with appear < disappear, got {(start, end)}"
                )

    def visible(self, t: float) -> bool:
        return not self.windows or any(start <= t < end for start, end in self.windows)


@dataclass(frozen=True)
class Waypoints:
    """Straight legs between points (world, m) at the given speeds (m/s, one per leg); then stays."""

    points: tuple[tuple[float, float, float], ...]
    speeds_m_s: tuple[float, ...]

    def __post_init__(self) -> None:
        if len(self.points) < 2 or len(self.speeds_m_s) != len(self.points) - 1:
            raise SettingsError(
                "waypoints need at least 2 points and one speed per leg (len(points) - 1)"
            )
        for index, point in enumerate(self.points):
            _vector(f"points[{index}]", point)
        if not all(math.isfinite(s) and s > 0 for s in self.speeds_m_s):
            raise SettingsError(f"waypoint speeds_m_s must be > 0 m/s, got {self.speeds_m_s}")

    def _legs(self) -> tuple[np.ndarray, np.ndarray]:
        pts = np.asarray(self.points, dtype=float)
        durations = np.linalg.norm(np.diff(pts, axis=0), axis=1) / np.asarray(self.speeds_m_s)
        return pts, np.concatenate([[0.0], np.cumsum(durations)])

    @property
    def duration_s(self) -> float:
        return float(self._legs()[1][-1])

    def position(self, t: float) -> np.ndarray:
        pts, starts = self._legs()
        if t <= 0:
            return pts[0].copy()
        leg = int(np.searchsorted(starts, t, side="right")) - 1
        if leg >= len(pts) - 1:
            return pts[-1].copy()
        span = starts[leg + 1] - starts[leg]
        s = (t - starts[leg]) / span if span > 0 else 1.0
        return pts[leg] + s * (pts[leg + 1] - pts[leg])

    @property
    def max_speed_m_s(self) -> float:
        return float(max(self.speeds_m_s))


@dataclass(frozen=True)
class Sinusoid:
    """``centre + amplitude * sin(2 pi f t + phase)`` per axis (world, m; Hz; rad)."""

    centre: tuple[float, float, float]
    amplitude_m: tuple[float, float, float]
    frequency_hz: float
    phase_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        _vector("centre", self.centre)
        _vector("amplitude_m", self.amplitude_m)
        _vector("phase_rad", self.phase_rad)
        if not (math.isfinite(self.frequency_hz) and self.frequency_hz > 0):
            raise SettingsError(f"frequency_hz must be > 0, got {self.frequency_hz}")

    def position(self, t: float) -> np.ndarray:
        w = 2 * math.pi * self.frequency_hz
        return np.asarray(self.centre) + np.asarray(self.amplitude_m) * np.sin(
            w * t + np.asarray(self.phase_rad)
        )

    @property
    def max_speed_m_s(self) -> float:
        return float(2 * math.pi * self.frequency_hz * np.linalg.norm(self.amplitude_m))


@dataclass(frozen=True)
class RandomWalk:
    """A seeded, smooth random walk: velocity is an Ornstein-Uhlenbeck process, clipped to a box.

    Sampled on a grid of ``step_s`` and interpolated linearly, so ``position(t)``
    is the same for any query order.  The speed never exceeds ``max_speed_m_s``.
    """

    start: tuple[float, float, float]
    max_speed_m_s: float
    duration_s: float
    seed: int = 0
    box_half_m: tuple[float, float, float] = (0.2, 0.2, 0.1)
    step_s: float = 0.01

    def __post_init__(self) -> None:
        start = _vector("start", self.start)
        half = _vector("box_half_m", self.box_half_m)
        for name in ("max_speed_m_s", "duration_s", "step_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise SettingsError(f"random walk {name} must be > 0, got {value}")
        count = math.ceil(self.duration_s / self.step_s) + 2
        if count > 10**6:
            raise SettingsError("random walk duration_s / step_s must be at most 1e6 samples")
        rng = np.random.default_rng(self.seed)
        points = np.empty((count, 3))
        points[0] = start
        velocity = np.zeros(3)
        tau = 0.5  # s, correlation time of the velocity
        for i in range(1, count):
            velocity += -velocity * self.step_s / tau + self.max_speed_m_s * math.sqrt(
                2 * self.step_s / tau
            ) * rng.standard_normal(3)
            speed = float(np.linalg.norm(velocity))
            if speed > self.max_speed_m_s:
                velocity *= self.max_speed_m_s / speed
            nxt = points[i - 1] + velocity * self.step_s
            out = np.abs(nxt - start) > half
            velocity[out] = -velocity[out]
            points[i] = np.clip(nxt, start - half, start + half)
        # Not a field: kept out of asdict (results.json) and of comparisons.
        object.__setattr__(self, "_samples", points)

    def position(self, t: float) -> np.ndarray:
        x = min(max(t, 0.0), self.duration_s) / self.step_s
        i = int(x)
        s = x - i
        samples: np.ndarray = self.__dict__["_samples"]  # set in __post_init__, not a field
        return (1 - s) * samples[i] + s * samples[i + 1]


@dataclass(frozen=True)
class Throw:
    """A ballistic throw from ``start`` with ``velocity`` (world, m, m/s) under gravity."""

    start: tuple[float, float, float]
    velocity_m_s: tuple[float, float, float]

    def __post_init__(self) -> None:
        _vector("start", self.start)
        _vector("velocity_m_s", self.velocity_m_s)

    def position(self, t: float) -> np.ndarray:
        t = max(t, 0.0)
        return (
            np.asarray(self.start)
            + np.asarray(self.velocity_m_s) * t
            - np.array([0.0, 0.0, 0.5 * GRAVITY * t * t])
        )


@dataclass(frozen=True)
class Static:
    """A target that stays at ``point`` (world, m)."""

    point: tuple[float, float, float]

    def __post_init__(self) -> None:
        _vector("point", self.point)

    def position(self, t: float) -> np.ndarray:
        return np.asarray(self.point, dtype=float).copy()

    max_speed_m_s: float = 0.0


@dataclass(frozen=True)
class Jump:
    """At ``start`` until ``time_s``, then at once at ``end`` (world, m): a saccade's target."""

    start: tuple[float, float, float]
    end: tuple[float, float, float]
    time_s: float

    def __post_init__(self) -> None:
        _vector("start", self.start)
        _vector("end", self.end)
        if not (math.isfinite(self.time_s) and self.time_s >= 0):
            raise SettingsError(f"jump time_s must be >= 0 s, got {self.time_s}")

    def position(self, t: float) -> np.ndarray:
        return np.asarray(self.start if t < self.time_s else self.end, dtype=float).copy()


Path = Waypoints | Sinusoid | RandomWalk | Throw | Static | Jump
