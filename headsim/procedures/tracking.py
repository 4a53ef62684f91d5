"""Tracking a moving target with Model 1 (neck and eyes), one fixation per time."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from headsim.active.events import FixationStarted, MeasurementDone, PhaseStarted
from headsim.active.measurement import HeadKnowledge, Measurement, Target
from headsim.active.model1 import measure_model1
from headsim.active.neck_servo import NeckServo
from headsim.codec import declared, doc
from headsim.head.servo_head import ServoHead
from headsim.procedures.contract import Procedure, register
from headsim.runs.context import (
    head,
    record_measurement,
    servo_config,
)
from headsim.runs.events import Hub
from headsim.runs.outcomes import MeasurementRecord
from headsim.runs.table import cell, mm
from headsim.runs.targets import marker_target
from headsim.scenario.scene import (
    RANDOM_BOX,
    finite_number,
    random_points_head,
    start_head_to_world,
    tuple3,
)
from headsim.scenario.schema import interpolate_option
from headsim.scenario.spec import (
    MARKER_BODIES,
    STREAM_MOVING,
    CalibrationSpec,
    MovingTarget,
    Scenario,
    SceneSpec,
)
from headsim.scenario.tables import MISSING, Context, Table, describe_value
from headsim.sim import names
from headsim.sim.declared import Array, Choice, Section, Setting, Text
from headsim.sim.events import EventSink
from headsim.sim.settings import HeadSettings


@declared
class TrackingResult:
    """Tracking a moving target with Model 1: times, s; waypoints and errors in W, m."""

    times_s: np.ndarray = doc("each fixation's time, s")
    waypoints_world_m: list[tuple[float, float, float]] = doc("the path's waypoints in W, m")
    errors_world_m: np.ndarray = doc("each fixation's error in W, m")
    renders_first: int = doc("renders of the first fixation")
    renders_after_mean: float = doc("mean renders per fixation after it")

    def summary_lines(self, paper: bool) -> list[str]:
        """One line: the fixations made, their error in W and their renders."""
        errors = np.asarray(self.errors_world_m, dtype=float)
        finite = errors[np.isfinite(errors)]
        return [
            f"Tracking with the neck (Model 1): {len(finite)} of {len(errors)} fixations; error in W "
            f"mean {mm(float(finite.mean()) if finite.size else None)} mm, max "
            f"{mm(float(finite.max()) if finite.size else None)} mm; renders {self.renders_first} for the "
            f"first fixation, {cell(self.renders_after_mean, '.1f')} per fixation after"
        ]


@dataclass(frozen=True)
class TrackingRun:
    """A moving target followed with the neck model: one measurement per fixation, time in s."""

    times_s: np.ndarray
    measurements: tuple[Measurement, ...]

    @property
    def errors_world_m(self) -> np.ndarray:
        """(N,) 3-D error of each fixation in W, m (NaN where it failed)."""
        return np.array(
            [np.linalg.norm(m.estimate_world_m - m.truth_world_m) for m in self.measurements]
        )


def track_moving_target(
    head: ServoHead,
    servo: NeckServo,
    target: Target,
    body: str,
    trajectory: Callable[[float], np.ndarray],
    times_s: Sequence[float] | np.ndarray,
    knowledge: HeadKnowledge | None = None,
    sink: EventSink | None = None,
) -> TrackingRun:
    """Move ``body`` along ``trajectory(t)`` (world, m) and fixate it at each time with Model 1.

    The servo's Jacobian carries from one fixation to the next, so after the
    first fixation each one starts from the last and takes few renders.  A
    target that left both views since is searched for around the last
    fixation (:func:`headsim.active.search.find_neck_view`), then from the start pose.
    ``sink``: where each fixation ("<target> 1", ...) and measurement is reported
    (None: the head's sink).
    """
    sink = head.sink if sink is None else sink
    measurements = []
    fixations: list[tuple[int, int, int]] = []  # where the target was seen, in steps
    for k, t in enumerate(times_s):
        sink.emit(FixationStarted(f"{target.name} {k + 1}"))
        head.truth.set_body_pose(body, trajectory(float(t)))
        m = measure_model1(head, servo, target, knowledge, last_seen=fixations[-2:])
        sink.emit(MeasurementDone(m, float(t)))
        measurements.append(m)
        if m.ok:
            fixations.append(servo.steps())
    return TrackingRun(np.asarray(times_s, dtype=float), tuple(measurements))


def run_tracking(
    scenario: Scenario, hub: Hub, knowledge: HeadKnowledge, label: str
) -> tuple[list[MeasurementRecord], TrackingResult]:
    """Follow the moving target with Model 1 (neck and eyes), one fixation per time."""
    moving = scenario.scene.moving
    assert moving is not None
    times = moving.times_s
    with head(hub, "default", scenario) as sim:
        truth = {f"{moving.name} {k + 1}": moving.position(float(t)) for k, t in enumerate(times)}
        hub.emit(PhaseStarted("measurement", sim.truth, knowledge, truth))
        target = marker_target(moving.name, moving.body)
        run = track_moving_target(
            sim,
            NeckServo(sim, servo_config(scenario)),
            target,
            moving.body,
            moving.position,
            times,
            knowledge,
        )
        steps = hub.steps
    records = [
        record_measurement(hub, m, label, step, float(t))
        for m, step, t in zip(run.measurements, steps, times, strict=True)
    ]
    errors = run.errors_world_m
    renders = [m.renders for m in run.measurements]
    experiment = TrackingResult(
        times_s=times,
        waypoints_world_m=list(moving.waypoints_world_m),
        errors_world_m=errors,
        renders_first=renders[0] if renders else 0,
        renders_after_mean=float(np.mean(renders[1:])) if len(renders) > 1 else float("nan"),
    )
    return records, experiment


def read_moving_scene(table: Table, ctx: Context, settings: HeadSettings, seed: int) -> SceneSpec:
    """``[scene.moving_target]`` in the default scene."""
    return SceneSpec(scene="default", moving=_read_moving(table, ctx, settings, seed))


def _read_moving(table: Table, ctx: Context, settings: HeadSettings, seed: int) -> MovingTarget:
    """``[scene.moving_target]``: a marker moved along waypoints, explicit or random."""
    moving = table.section(MOVING)
    if moving is None:
        raise table.fail("moving_target", "missing", "a [scene.moving_target] table")
    name, body, duration, steps = (moving.setting(d) for d in (_NAME, _BODY, _DURATION, _STEPS))
    allowed = "waypoints_head_m or waypoints_world_m (arrays of [x, y, z], at least 2) or [scene.moving_target.random]"
    given = []
    for key, frame in ((_IN_HEAD.name, "head"), (_IN_WORLD.name, "world")):
        value = moving.data.get(key, MISSING)
        moving.has(key)
        if value is MISSING:
            continue
        if (
            not isinstance(value, list)
            or len(value) < 2
            or not all(isinstance(p, list) and len(p) == 3 for p in value)
        ):
            raise moving.fail(
                key, f"must be an array of [x, y, z], got {describe_value(value)}", allowed
            )
        points = np.array(
            [[finite_number(moving, f"{key}[{i}]", c) for c in p] for i, p in enumerate(value)]
        )
        given.append(start_head_to_world(settings, points) if frame == "head" else points)
    random_table = moving.section(RANDOM)
    if random_table is not None:
        count = random_table.setting(_COUNT)
        rng = np.random.default_rng([seed, STREAM_MOVING])
        given.append(start_head_to_world(settings, random_points_head(random_table, count, rng)))
        random_table.done()
    moving.done()
    if len(given) != 1:
        raise moving.fail("waypoints_head_m", "missing" if not given else "given twice", allowed)
    waypoints = tuple(tuple3(p) for p in given[0])
    return MovingTarget(name, body, waypoints, duration, steps)


def read_options(table: Table, calibration: CalibrationSpec | None) -> dict[str, Any]:
    """``[experiment]``: ``interpolate``."""
    return interpolate_option(table)


def _fixations(scenario: Scenario) -> int:
    return scenario.scene.moving.steps if scenario.scene.moving else 0


#: The scenario tables only it reads.
_NAME = Text("name", "moving_target", "The moving target's name.", max_length=60)
_BODY = Choice("body", tuple(MARKER_BODIES), names.MARKERS[0], "The marker body that moves.")  # fmt: skip
_DURATION = Setting("duration_s", 10.0, 0.0, 3600.0, "s", "Time to pass all waypoints, s.", lo_open=True)  # fmt: skip
_STEPS = Setting("steps", None, 1, 10000, "", "Fixations, at equal intervals from t = 0. Required.", integer=True, required=True)  # fmt: skip
_WAYPOINTS = "an array of [x, y, z], at least 2"
_IN_HEAD = Array("waypoints_head_m", _WAYPOINTS, "Waypoints [[x, y, z], ...] in H at the start pose, at least 2, passed at equal times, m.")  # fmt: skip
_IN_WORLD = Array("waypoints_world_m", _WAYPOINTS, "Waypoints [[x, y, z], ...] in W, at least 2, m.")  # fmt: skip
_COUNT = Setting("waypoints", None, 2, 1000, "", "Number of random waypoints.", integer=True, required=True)  # fmt: skip
MOVING = Section("scene.moving_target", "The marker moved along waypoints (procedure `tracking`).", (_NAME, _BODY, _DURATION, _STEPS, _IN_HEAD, _IN_WORLD))  # fmt: skip
RANDOM = Section("scene.moving_target.random", "Random waypoints drawn from the seed instead.", (_COUNT, *RANDOM_BOX))  # fmt: skip


TRACKING = register(
    Procedure(
        "tracking",
        "default",
        run_tracking,
        TrackingResult,
        summary=TrackingResult.summary_lines,
        options=read_options,
        read_scene=read_moving_scene,
        fixations=_fixations,
        keys=(MOVING, RANDOM),
        rank=40,
    )
)


__all__ = ["TRACKING", "TrackingResult", "TrackingRun", "run_tracking", "track_moving_target"]
