"""The ``headsim`` command line."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from headsim import names
from headsim.settings import PRESETS, SettingsError, preset


def _snapshot(args: argparse.Namespace) -> int:
    from headsim.snapshot import take_snapshot

    settings = preset(args.preset, seed=args.seed)
    written = take_snapshot(
        args.out,
        args.scene,
        settings,
        neck_yaw=args.neck_yaw,
        neck_pitch=args.neck_pitch,
        eye=args.eye,
    )
    print(f"scene {args.scene!r}, preset {args.preset!r}: wrote")
    for kind, path in written.items():
        print(f"  {kind:9s} {path}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="headsim",
        description="MuJoCo testbed for vergence-based active stereo vision on humanoid heads.",
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    snap = commands.add_parser(
        "snapshot",
        help="render both eye cameras and write PNGs and the ground truth as JSON",
        description="Pose the head, render both cameras, and write cam1.png, cam2.png, "
        "overview.png (true projections marked) and truth.json to --out.",
    )
    snap.add_argument("--out", required=True, help="output directory (created if missing)")
    snap.add_argument(
        "--scene",
        default="default",
        help=f"scene: {', '.join(sorted(names.SCENES))} or an MJCF path",
    )
    snap.add_argument(
        "--preset", default="ideal", choices=sorted(PRESETS), help="camera preset (default: ideal)"
    )
    snap.add_argument(
        "--eye", type=float, default=0.0, help="eye-motor angle, rad, positive inward"
    )
    snap.add_argument("--neck-yaw", type=float, default=0.0, help="neck yaw, rad")
    snap.add_argument(
        "--neck-pitch", type=float, default=0.0, help="neck pitch, rad, positive looks up"
    )
    snap.add_argument("--seed", type=int, default=0, help="seed of the image noise")
    snap.set_defaults(func=_snapshot)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (SettingsError, ValueError) as err:
        print(f"headsim: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
