"""Throughput of Model 2 on many points, next to plain numpy references.

    python benchmarks/estimators_throughput.py [--points 1000000] [--json out.json]

Prints points per second for ``headsim.estimators.model2`` (all checks and
flags, no covariance), for it with the first-order covariance, and for two
bare numpy references on the same arrays: eqs. (4)-(5) alone, and eqs.
(4)-(11) without any checks.  The ratios survive a change of machine.
"""

from __future__ import annotations

import argparse
import platform

import numpy as np

from headsim.estimators.throughput import run
from headsim.files import write_json_atomic


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000, help="number of points")
    parser.add_argument("--repeats", type=int, default=7, help="timing repeats (best is kept)")
    parser.add_argument("--json", metavar="PATH", help="also write the figures to PATH as JSON")
    args = parser.parse_args(argv)
    figures = run(args.points, args.repeats)
    print(
        f"{platform.processor() or platform.machine()}, numpy {np.__version__}, "
        f"{args.points:,} points ({int(figures['n_valid']):,} valid, "
        f"max error {figures['max_abs_error_m']:.1e} m)"
    )
    for key in ("model2", "model2_with_covariance", "numpy_eq4_5", "numpy_eq4_11"):
        print(f"  {key:24s} {figures[key + '_points_per_s'] / 1e6:8.2f} M points/s")
    print(f"  model2 / bare eqs. (4)-(5):  {figures['model2_over_numpy_eq4_5']:.2f} of the speed")
    print(f"  model2 / bare eqs. (4)-(11): {figures['model2_over_numpy_eq4_11']:.2f} of the speed")
    if args.json:
        write_json_atomic(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
