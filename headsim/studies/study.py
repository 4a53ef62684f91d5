"""Calibrated stereo against the active method, after calibration and after the cameras change.

Pure orchestration over :mod:`headsim.stereo`, :mod:`headsim.active` and
:mod:`headsim.active.principal`; every error is estimate minus the simulator's truth
in the head frame H, and "% of depth" divides by the true z_h.

**Methods** (:data:`headsim.studies.methods.METHODS`), each with its own calibration
(:func:`headsim.studies.calibrations.calibrate_methods`):

- ``stereo``: Zhang calibration on chessboard views at eye angle 0, then
  triangulation at eye angle 0 (the paper's Sec. VI-B baseline).
- ``active_v_known``: Model 2 with the Sec. V initial directions, the servo on
  the image centre's column and the principal point's v from the Zhang
  calibration (the paper's Table V condition).
- ``active_centre``: the same with the image centre's row (Table VI: no
  intrinsic parameter at all).
- ``active_extended``: the same with v0 and kx/ky fitted from the Sec. V
  samples themselves (``calibrate_head``'s extended calibration).
- ``active_fixed_point``: beyond the paper: the principal point found as the
  fixed point of a zoom (images only, :mod:`headsim.active.principal`), the servo on
  its column, and the initial directions, v0 and kx/ky calibrated as for
  ``active_extended`` with that servo.
- ``active_refound``: ``active_fixed_point`` that finds the fixed point again
  (one more zoom, images only) on the head it measures, keeping its initial
  directions and kx/ky: on the principal point's column the initial
  direction is the mount yaw, which no intrinsic change moves.

**Conditions.**  A :class:`headsim.studies.conditions.Condition` is a head to measure on, the targets to
measure, and whether the methods keep the calibration made on the study's
base head (``"kept"``: the cameras changed after calibration, e.g. a zoom) or
are calibrated again on this head (``"redone"``).  :func:`headsim.studies.conditions.run_conditions`
measures every method on every target of every condition.

**Experiments** are described in ``study_experiments.toml`` (read by
:mod:`headsim.studies.catalogue`): the comparison (the six target positions of Tables V
and VI, then the same targets after the changes it lists, with the calibrations kept, on
the paper's cameras and with centred principal points) and the sweeps.  :func:`headsim.studies.study_output.write_experiment` writes
``<name>.csv`` (a row per condition and method), ``<name>_targets.csv`` (a
row per target), ``<name>.json`` and ``<name>.png`` beside ``results.json``,
which indexes every experiment written to the directory.  The realistic
head's error budget (``--experiment budget``) is :mod:`headsim.studies.error_budget`.

    headsim study --experiment compare --out out/study
    headsim study --sweep depth --out out/study [--fast]
    headsim study --experiment budget --out out/study [--fast]
    headsim study --all --out out/study

Its options are the ``headsim`` parser's (:func:`headsim.cli.parser.add_study_arguments`);
``python -m headsim.studies.study`` is a deprecated alias of ``headsim study``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from headsim.runs.progress import Progress, Status, quiet
from headsim.studies.calibrations import CalibrationCache
from headsim.studies.catalogue import (
    SWEEPS,
    compare_experiment,
    run_experiment,
    sweep_experiment,
)
from headsim.studies.methods import StudyConfig
from headsim.studies.study_output import print_result, write_experiment

#: Printed by the deprecated alias ``python -m headsim.studies.study``.
ALIAS_NOTE = "note: python -m headsim.studies.study is deprecated; run: headsim study ..."


def run(args: argparse.Namespace) -> int:
    """``headsim study``: run what ``args`` asks for; 0 on success."""
    make = StudyConfig.quick if args.fast else StudyConfig
    config = make(preset=args.preset, seed=args.seed)
    progress: Progress = quiet if args.quiet else Status("headsim study")
    cache = CalibrationCache(config, progress)
    if args.experiment == "budget":
        return _budget(args, progress)
    if args.all:
        experiments = [compare_experiment(config)] + [
            sweep_experiment(name, config) for name in SWEEPS
        ]
    elif args.experiment:
        experiments = [compare_experiment(config)]
    else:
        experiments = [sweep_experiment(args.sweep, config)]
    for experiment in experiments:
        result = run_experiment(
            experiment,
            config,
            progress=progress,
            cache=cache,
            workers=args.workers,
            scheduler=args.scheduler,
        )
        files = write_experiment(result, args.out)
        progress(
            f"{experiment.name}: {result.seconds:.1f} s; wrote {', '.join(map(str, files.values()))}"
        )
        print_result(result)
    return _budget(args, progress) if args.all else 0


def _budget(args: argparse.Namespace, progress: Progress) -> int:
    """The realistic head's error budget (:mod:`headsim.studies.error_budget`); 0 on success."""
    from headsim.studies import error_budget

    start = time.perf_counter()
    rows = error_budget.run_budget(
        fast=args.fast,
        seed=args.seed,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=progress,
    )
    files = error_budget.write_budget(rows, args.out, args.fast)
    progress(
        f"budget: {time.perf_counter() - start:.1f} s; wrote {', '.join(map(str, files.values()))}"
    )
    print(files["md"].read_text(), end="")
    failed = [f"{r['condition']}: {r['failures']}" for r in rows if r["failures"]]
    for line in failed:
        progress(f"budget: failed: {line}")
    return 1 if failed else 0


if __name__ == "__main__":  # the deprecated alias: this process becomes ``headsim study``
    print(ALIAS_NOTE, file=sys.stderr, flush=True)
    os.execv(sys.executable, [sys.executable, "-m", "headsim.cli", "study", *sys.argv[1:]])
