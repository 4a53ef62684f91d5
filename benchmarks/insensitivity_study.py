"""Calibrated stereo against the active method: Tables V/VI, changes after calibration, sweeps.

Each run prints progress on stderr, a table per experiment on stdout, and
writes ``<name>.csv``, ``<name>_targets.csv``, ``<name>.json`` and
``<name>.png`` beside ``results.json`` in --out (``headsim study``, whose options it takes):

    python benchmarks/insensitivity_study.py --experiment compare --out out/study
    python benchmarks/insensitivity_study.py --sweep depth --out out/study
    python benchmarks/insensitivity_study.py --all --out out/study [--fast]

Sweeps: depth, focal, principal, k1, noise, encoder.  ``--fast`` runs small
calibrations and two values per sweep (a smoke run of about a minute).
"""

from __future__ import annotations

import sys

from headsim.cli import main

if __name__ == "__main__":
    raise SystemExit(main(["study", *sys.argv[1:]]))
