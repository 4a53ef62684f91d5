"""The documentation's screenshot of the quick start's recording, regenerated.

Runs today's quick start with ``--rrd`` (``headsim run quickstart``, full, seed 0),
serves the recording with ``rerun --serve-web``, opens it in Rerun's web viewer in
headless Chromium and takes a screenshot (tests/run/viewer), judges every view by its
pixels, and writes docs/recording.png (the README, the home page and "Record and view
live" show it) only when every view drew:

    python tools/recording_screenshot.py            # Debian: apt-get install -y chromium

``--scenario NAME [--fast]`` takes another scenario's; a room scenario's layout is
judged by its own views (the textured room, the cameras, each eye's fovea, camera 1's
template and camera 2's matched patch): docs/recording-room.png is

    python tools/recording_screenshot.py --scenario natural_field --fast --png docs/recording-room.png

Exit status: 0 written, 1 a view did not draw (the screenshot is left in --out, the
documentation's untouched), 2 the quick start failed, 3 Chromium or the viewer could
not be run.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the viewer helpers live in tests/run/viewer

import cv2  # noqa: E402

from headsim.cli import main as headsim  # noqa: E402
from tests.run.viewer.browser import (  # noqa: E402
    ViewerCheckError,
    chromium_path,
    screenshot,
    serve_file,
)
from tests.run.viewer.judge import judge, judge_room  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "recording_screenshot")
    parser.add_argument("--png", type=Path, default=ROOT / "docs" / "recording.png")
    parser.add_argument("--chromium", help="Chromium's executable (default: on PATH)")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds to wait, at most")
    parser.add_argument("--scenario", default="quickstart", help="the scenario to run")
    parser.add_argument("--fast", action="store_true", help="its fast variant")
    args = parser.parse_args(argv)
    executable = args.chromium or chromium_path()
    if executable is None or shutil.which(executable) is None:
        print(
            "recording_screenshot: error: Chromium is not installed "
            f"({executable or 'none on PATH'}; Debian/Ubuntu: apt-get install -y chromium)",
            file=sys.stderr,
        )
        return 3
    rrd = args.out / "recording.rrd"
    command = ["run", args.scenario, "--out", str(args.out), "--rrd", str(rrd), "--quiet"]
    if headsim(command + (["--fast"] if args.fast else [])) != 0:
        print(f"recording_screenshot: error: {args.scenario} failed", file=sys.stderr)
        return 2
    results = json.loads((args.out / "results.json").read_text())
    try:
        with serve_file(rrd) as url:
            image = screenshot(url, timeout_s=args.timeout, executable=executable)
    except ViewerCheckError as err:
        print(f"recording_screenshot: error: {err}", file=sys.stderr)
        return 3
    shot = args.out / "viewer.png"
    # Lossless, compressed harder than OpenCV's default: the page ships with the docs.
    cv2.imwrite(str(shot), cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_PNG_COMPRESSION, 9])
    room = results.get("scenario", {}).get("scene", {}).get("room") is not None
    verdict = judge_room(image) if room else judge(image)
    for name, figure in verdict.figures.items():
        print(f"  {name:32s} {figure:g}")
    renders = results["render_counts"]["overall"]["total"]
    print(f"{args.scenario} drew {renders} renders; its recording: {rrd}")
    if not verdict.ok:
        for problem in verdict.problems:
            print(f"  problem: {problem}")
        print(f"recording_screenshot: a view did not draw; see {shot}", file=sys.stderr)
        return 1
    shutil.copyfile(shot, args.png)
    print(f"wrote {args.png} ({image.shape[1]}x{image.shape[0]})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
