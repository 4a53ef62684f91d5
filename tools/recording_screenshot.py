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

``--mcap`` records the run as ROS 2 messages instead (``headsim run ... --mcap``),
converts the file with Rerun's own importer (``rerun mcap convert``) and shows that, in
Rerun's default layout for it; it is judged drawn when the page shows more than a blank
screen: docs/mcap-quickstart.png ("The same procedures on a real head") is

    python tools/recording_screenshot.py --mcap --png docs/mcap-quickstart.png

Exit status: 0 written, 1 a view did not draw (the screenshot is left in --out, the
documentation's untouched), 2 the quick start failed, 3 Chromium or the viewer could
not be run.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the viewer helpers live in tests/run/viewer

import cv2  # noqa: E402

from headsim.cli import main as headsim  # noqa: E402
from tests.run.viewer.browser import (  # noqa: E402
    ViewerCheckError,
    chromium_path,
    rerun_executable,
    screenshot,
    serve_file,
)
from tests.run.viewer.judge import ViewJudgement, drawn, judge, judge_room  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "recording_screenshot")
    parser.add_argument("--png", type=Path, default=ROOT / "docs" / "recording.png")
    parser.add_argument("--chromium", help="Chromium's executable (default: on PATH)")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds to wait, at most")
    parser.add_argument("--scenario", default="quickstart", help="the scenario to run")
    parser.add_argument("--fast", action="store_true", help="its fast variant")
    parser.add_argument(
        "--mcap", action="store_true", help="record ROS 2 messages and show Rerun's import of them"
    )
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
    mcap = args.out / "recording.mcap"
    record = ["--mcap", str(mcap)] if args.mcap else ["--rrd", str(rrd)]
    command = ["run", args.scenario, "--out", str(args.out), *record, "--quiet"]
    if headsim(command + (["--fast"] if args.fast else [])) != 0:
        print(f"recording_screenshot: error: {args.scenario} failed", file=sys.stderr)
        return 2
    if args.mcap:
        try:
            convert = [rerun_executable(), "mcap", "convert", str(mcap), "-o", str(rrd)]
            convert += ["--application-id", f"{args.scenario}.mcap"]
            subprocess.run(convert, check=True, capture_output=True, timeout=args.timeout)
        except (ViewerCheckError, subprocess.SubprocessError) as err:
            print(f"recording_screenshot: error: rerun mcap convert: {err}", file=sys.stderr)
            return 3
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
    if args.mcap:  # Rerun's own layout of the import: judged only as drawn
        shown = drawn(image)
        verdict = ViewJudgement({"page_std": float(image.std())}, () if shown else ("blank page",))
    else:
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
