"""``headsim snapshot``: render both eye cameras and write PNGs and the ground truth.

The simulator loads inside the command, not here.
"""

from __future__ import annotations

import argparse

from headsim.errors import (
    BadInput,
)
from headsim.runs.outputs import Outputs


def snapshot_command(args: argparse.Namespace) -> int:
    from headsim.sim.settings import preset
    from headsim.sim.snapshot import take_snapshot

    settings = preset(args.preset, seed=args.seed)
    outputs = Outputs()
    try:
        out = outputs.directory(args.out, "--out")
        written = take_snapshot(
            out,
            args.scene,
            settings,
            neck_yaw=args.neck_yaw,
            neck_pitch=args.neck_pitch,
            eye=args.eye,
        )
    except ValueError as err:  # a pose beyond a joint's range, a bad scene
        raise BadInput(str(err)) from err
    finally:
        outputs.remove_empty_created()
    print(f"scene {args.scene!r}, preset {args.preset!r}: wrote")
    for kind, path in written.items():
        print(f"  {kind:9s} {path}")
    return 0
