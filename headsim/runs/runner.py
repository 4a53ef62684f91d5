"""Running a scenario: calibrate if asked, run the procedure, collect the results.

The calibration is :mod:`headsim.runs.calibrate`'s (or a calibration file's, as
the scenario reader read it); the procedure is found by its name in
:mod:`headsim.procedures.contract` (the built-in ones are :mod:`headsim.procedures`).
What a run shows while it goes (progress, the Rerun recording) follows its
events: the runner gives the simulator (and through it the servos and the
procedure) a :class:`headsim.runs.events.Hub` as event sink, and the hub passes
every event on to the run's subscribers.  The runner adds its own events: the
calibration's report and the finished run.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace

from headsim.active.calibration_file import head_hash, read_calibration
from headsim.active.calibration_report import CalibrationReport
from headsim.procedures.contract import get
from headsim.runs.calibrate import calibrate
from headsim.runs.context import told
from headsim.runs.events import CalibrationDone, Hub, RunFinished, Subscriber
from headsim.runs.outcomes import MeasurementRecord, RunRenders
from headsim.runs.result import RunResult
from headsim.scenario.spec import Scenario
from headsim.sim.events import RenderCounts


def calibrate_scenario(
    scenario: Scenario, subscribers: Sequence[Subscriber] = ()
) -> CalibrationReport:
    """Only the scenario's Sec. V calibration (``headsim calibrate``): its report.

    ``status`` is OK or why it failed; ``renders`` every image it drew, by kind;
    ``rendered_frames`` their pixels, in full frames.
    """
    spec = scenario.experiment.calibration
    if spec is None or spec.source is not None:
        raise ValueError("the scenario has no calibration to run ([experiment.calibration])")
    hub = Hub(subscribers)
    _, report = calibrate(scenario, hub)
    return replace(report, rendered_frames=hub.rendered_frames)


def run_scenario(scenario: Scenario, subscribers: Sequence[Subscriber] = ()) -> RunResult:
    """Run a checked scenario; the subscribers see every image, detection and result."""
    hub = Hub(subscribers)
    timing: dict[str, float] = {}
    renders = {"calibration": RenderCounts(), "experiment": RenderCounts()}
    rendered_frames = {"calibration": 0.0, "experiment": 0.0}
    knowledge, label = told(scenario), "none"
    calibration = None
    failures: list[str] = []
    spec = scenario.experiment.calibration
    if spec is not None and spec.source is not None:
        stored = scenario.stored_calibration  # as the reader read it, unless the head changed
        if stored is None or stored.head_hash != head_hash(scenario.settings):
            stored = read_calibration(spec.source, scenario.settings)
        calibration = stored.report
        hub.emit(CalibrationDone(calibration))
        knowledge, label = stored.knowledge, "calibrated"
    elif spec is not None:
        start = time.perf_counter()
        run, calibration = calibrate(scenario, hub)
        timing["calibration"] = time.perf_counter() - start
        renders["calibration"] = calibration.renders
        rendered_frames["calibration"] = hub.rendered_frames
        if run is None:
            failures.append(f"calibration: {calibration.status_text}")
        else:
            knowledge, label = run.knowledge, "calibrated"
    records: list[MeasurementRecord] = []
    experiment: object | None = None
    procedure = get(scenario.experiment.procedure)
    if not failures:
        start = time.perf_counter()
        before = hub.renders
        ran, experiment = procedure.run(scenario, hub, knowledge, label)
        records = list(ran)
        timing["experiment"] = time.perf_counter() - start
        renders["experiment"] = hub.renders - before
        rendered_frames["experiment"] = hub.rendered_frames - rendered_frames["calibration"]
    failures += [
        f"{r.measurement.name}: {r.measurement.status_text}"
        for r in records
        if not r.measurement.ok
    ]
    if experiment is not None:
        failures += procedure.failures(experiment)
    timing["total"] = sum(timing.values())
    result = RunResult(
        scenario=scenario,
        calibration=calibration,
        records=tuple(records),
        experiment=experiment,
        renders=RunRenders(
            calibration=renders["calibration"],
            experiment=renders["experiment"],
            in_measurements=sum(r.measurement.renders for r in records),
        ),
        failures=tuple(failures),
        timing_s=timing,
        rendered_frames={
            **rendered_frames,
            "total": rendered_frames["calibration"] + rendered_frames["experiment"],
        },
    )
    hub.emit(RunFinished(result))
    return result


__all__ = ["calibrate_scenario", "run_scenario"]
