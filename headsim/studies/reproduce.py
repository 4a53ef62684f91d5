"""``headsim reproduce``: every experiment of the paper's Sec. VI on one head, in one report.

One head (the scenarios' ``paper`` head) is calibrated once (Sec. V, the
``calibration`` scenario's targets) into ``DIR/head.json``; then, spread over
``--workers`` processes, each experiment runs with that calibration.  The jobs, what
each reproduces and what each needs are described in ``reproduce_experiments.toml``
(the Tables V/VI job: :mod:`headsim.studies.paper_tables`; the study's other heads and
changes are left to ``headsim study``).

The head's calibration, Zhang's and the fixed points' run first, side by
side; then the longest experiments first, so that the workers finish together.
With ``--sweeps`` the study's insensitivity sweeps are added.  Every
experiment writes its files under ``DIR/<experiment>/`` as it finishes, and
``DIR/report.md`` (with ``DIR/figures/*.png``) is rewritten after each one, so
an interrupted run leaves a readable partial report.  A failed experiment is
reported as such beside the others.
"""

from __future__ import annotations

import functools
import importlib
import os
import statistics
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from headsim.errors import OutputNotWritable
from headsim.files import to_jsonable, write_json_atomic, write_text_atomic
from headsim.runs.progress import Status, quiet
from headsim.studies.catalogue import (
    REPRODUCE,
    STUDY_JOB,
    JobOutcome,
    ReproduceError,
)
from headsim.studies.jobs import (
    PlannedJob,
    job_error,
    run_plan,
    started_render_pool,
    stop_pool,
    terminate_children,
)
from headsim.studies.render_clock import CLOCK_RENDERS, RenderClock, cpu_s
from headsim.studies.reproduce_jobs import JOB_HOOKS, WORKER_MODULES, study_job
from headsim.studies.reproduce_report import main_figure, report_sections, report_text


def reproduce(
    out: str | Path,
    *,
    fast: bool = False,
    workers: int = 1,
    sweeps: bool = False,
    seed: int | None = None,
    progress: Callable[[str], None] = lambda _: None,
) -> dict[str, Any]:
    """Run everything, write DIR/report.md; returns the state (``status``: ok, failed, interrupted)."""
    from headsim.studies.catalogue import SWEEPS

    if not isinstance(workers, int) or not 1 <= workers <= 64:
        raise ReproduceError(f"--workers must be an integer from 1 to 64, got {workers!r}")
    if seed is not None and not 0 <= seed < 2**32:
        raise ReproduceError(f"--seed must be from 0 to 2**32 - 1, got {seed}")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ReproduceError(f"--out: {out} exists and is not a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputNotWritable(f"--out: cannot create {out}: {err.strerror}") from err
    start, epoch = time.perf_counter(), time.time()
    # The workers load what their jobs import (about 1 s) while this process makes its
    # clock, whose renders are then timed on a quiet machine.
    pool, clock = started_render_pool(workers, WORKER_MODULES, RenderClock)
    render_s = clock.sample(CLOCK_RENDERS[0])
    state: dict[str, Any] = {
        "status": "running",
        "out": out,
        "fast": fast,
        "workers": workers,
        "seed": 0 if seed is None else seed,
        "sweeps": [f"sweep_{name}" for name in SWEEPS] if sweeps else [],
        "render_s": render_s,
        "render_before_s": render_s,
        "wall_s": 0.0,
        "wall_over_render": 0.0,
    }
    outcomes: dict[str, JobOutcome] = {}
    calibration: dict[str, Any] | None = None
    #: Each job's worker, times since the start and CPU time, s: {"pid", "start", "end", "cpu_s"}.
    timeline: dict[str, dict[str, float]] = {"render_time": {"pid": os.getpid(), "start": 0.0}}
    timeline["render_time"]["end"] = time.time() - epoch

    drawing: threading.Thread | None = None  # the Tables V/VI figure, once its job ends

    def draw_tables() -> None:
        """The Tables V/VI PNG, once, on a thread of this process: drawing it (~0.3 s)
        must not hold back the job that another worker is ready to start."""
        nonlocal drawing
        tables = outcomes.get(STUDY_JOB)
        if tables is not None and "result" in tables.data:
            result = tables.data.pop("result")
            png = Path(tables.data["files"]["png"])

            def draw() -> None:
                from headsim.studies import plots

                try:
                    plots.plot_experiment(result, png)
                except Exception as err:  # a figure must not hide the numbers
                    progress(f"figure not drawn: {err!r}")

            drawing = threading.Thread(target=draw, daemon=True)
            drawing.start()

    def write_report(figure: bool = True) -> None:
        """report.md and report.json; the main figure (matplotlib, ~1 s) only when asked:
        at the end, and when interrupted.  The wall time counts the figure."""
        drawn = None
        if figure:
            try:
                draw_tables()
                if drawing is not None:  # pyplot's figures are one thread's at a time
                    drawing.join()
                drawn = main_figure(outcomes, calibration, out / "figures" / "main.png")
            except Exception as err:  # a figure must not hide the numbers
                progress(f"figure not drawn: {err!r}")
        state["wall_s"] = time.perf_counter() - start
        state["wall_over_render"] = state["wall_s"] / state["render_s"]
        write_text_atomic(out / "report.md", report_text(state, outcomes, calibration, drawn))
        write_json_atomic(
            out / "report.json",
            to_jsonable(
                {
                    "status": state["status"],
                    "seed": state["seed"],
                    "fast": fast,
                    "workers": workers,
                    "wall_s": state["wall_s"],
                    "render_s": state["render_s"],
                    "render_before_s": state["render_before_s"],
                    "render_after_s": state.get("render_after_s"),
                    "render_cpu_s": state.get("render_cpu_s"),
                    "cpu_s": state.get("cpu_s"),
                    "cpu_over_render_cpu": state.get("cpu_over_render_cpu"),
                    "render_samples_s": clock.times_s,
                    "wall_over_render": state["wall_over_render"],
                    "experiments": {
                        n: {"status": o.status, "wall_s": o.wall_s, "error": o.error}
                        for n, o in outcomes.items()
                    },
                    "timeline": timeline,
                    "rows": {
                        name: None
                        if rows is None
                        else [
                            {"quantity": r.quantity, "ours": r.ours, "verdict": r.verdict}
                            for r in rows
                        ]
                        for name, _, rows, _ in report_sections(state, outcomes, calibration)
                    },
                }
            ),
        )

    try:
        write_report(figure=False)
        progress("calibrating the head once (and its stereo pair, Zhang, beside it)")
        # matplotlib loads (about 1 s) while the workers run, not after them.
        threading.Thread(
            target=importlib.import_module, args=("headsim.studies.plots",), daemon=True
        ).start()
        path, sweep_cost = str(out), REPRODUCE.sweep_cost

        def args(done: dict[str, Any], name: str, after: tuple[str, ...]) -> tuple[Any, ...]:
            return (name, path, fast, seed, {job: done[job] for job in after})

        plan = [
            PlannedJob(
                name,
                JOB_HOOKS[job.hook],
                job.after,
                functools.partial(args, name=name, after=job.after),
                job.cost_of(fast),
            )
            for name, job in REPRODUCE.jobs.items()
        ] + [
            PlannedJob(n, study_job, (), functools.partial(args, name=n, after=()), sweep_cost)
            for n in state["sweeps"]
        ]

        def finished(
            name: str, data: dict[str, Any] | None, err: BaseException | None, wall_s: float, _: int
        ) -> None:
            nonlocal calibration
            error = "" if err is None else job_error(err)
            if data is not None and data.get("worker"):
                worker = data["worker"]
                timeline[name] = {
                    "pid": worker["pid"],
                    "start": worker["start"] - epoch,
                    "end": worker["end"] - epoch,
                    "cpu_s": worker["cpu_s"],
                }
            if name == "calibration":
                calibration = data
                if data is None:
                    outcomes["initial_directions"] = JobOutcome(
                        "initial_directions", "error", wall_s, error=error
                    )
                return
            if name in ("zhang", "fixed_point"):
                if data is None and STUDY_JOB not in outcomes:
                    outcomes[STUDY_JOB] = JobOutcome(STUDY_JOB, "error", wall_s, error=error)
                return
            if data is None:
                outcomes[name] = JobOutcome(name, "error", wall_s, error=error)
            else:
                failed = bool(data.get("results", {}).get("failures"))
                # The job's own time, not the time it waited for a worker.
                own = data.get("wall_s", data.get("seconds"))
                outcomes[name] = JobOutcome(
                    name, "failed" if failed else "ok", float(own) if own else wall_s, data
                )
            progress(f"{name}: {outcomes[name].status}")
            if name == STUDY_JOB:
                draw_tables()
            write_report(figure=False)

        def skipped(name: str, missing: str) -> None:
            if name not in outcomes:
                why = "no calibration to use" if missing == "calibration" else f"no {missing}"
                outcomes[name] = JobOutcome(name, "error", 0.0, error=why)

        ended = run_plan(plan, lambda: pool, finished, workers=workers, skipped=skipped, close=None)
        progress(f"scheduler: {ended}")
        # Every job ended and its files are written: the idle workers are stopped
        # rather than left to tear down their interpreters and GL contexts (~0.5 s).
        terminate_children()
        state["status"] = (
            "ok" if calibration and all(o.status == "ok" for o in outcomes.values()) else "failed"
        )
    except KeyboardInterrupt:
        state["status"] = "interrupted"
        # Stop the workers now: their experiments are lost, the finished ones are kept.
        stop_pool(pool)
        write_report()
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        timeline["shutdown"] = {"pid": os.getpid(), "start": 0.0, "end": time.time() - epoch}
        try:
            if state["status"] != "interrupted":
                state["render_after_s"] = clock.sample(CLOCK_RENDERS[1])
                # The unit is the quieter of the two medians: the machine's other load
                # only adds time, and a unit timed while it was busy would flatter the
                # ratio (a 44 ms median before against 33 ms after, on one run).
                state["render_s"] = min(state["render_before_s"], state["render_after_s"])
                # CPU time of the whole run (this process and its ended workers) over
                # one render's: the machine's other load moves it less than the wall
                # ratio, which is this times the cores a render keeps busy over the
                # cores the run keeps busy.
                before, after = CLOCK_RENDERS[0], CLOCK_RENDERS[0] + CLOCK_RENDERS[1]
                state["render_cpu_s"] = min(
                    statistics.median(clock.cpu_s[:before]),
                    statistics.median(clock.cpu_s[before:after]),
                )
                state["cpu_s"] = cpu_s()
                state["cpu_over_render_cpu"] = state["cpu_s"] / state["render_cpu_s"]
        finally:
            clock.close()
        timeline["render_time_end"] = {"pid": os.getpid(), "start": 0.0, "end": time.time() - epoch}
    write_report()
    return state


def main(args: Any) -> int:
    """``headsim reproduce``: exit 0 all ran, 1 an experiment failed, 2 bad input, 130 interrupted."""

    progress = quiet if getattr(args, "quiet", False) else Status("headsim reproduce")

    try:
        state = reproduce(
            args.out,
            fast=args.fast,
            workers=args.workers,
            sweeps=args.sweeps,
            seed=args.seed,
            progress=progress,
        )
    except KeyboardInterrupt:
        print(
            f"\nheadsim: interrupted: the report so far is in {Path(args.out) / 'report.md'}",
            file=sys.stderr,
        )
        return 130
    print(
        f"{state['status']}: {Path(args.out) / 'report.md'}; wall {state['wall_s']:.1f} s = "
        f"{state['wall_over_render']:.0f} x the median 640x480 render ({1e3 * state['render_s']:.1f} ms)"
    )
    return 0 if state["status"] == "ok" else 1
