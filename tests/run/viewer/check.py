"""Open a recording in Rerun's web viewer in headless Chromium and take a screenshot.

The command line over :mod:`tests.run.viewer.browser` (serving, Chromium,
the screenshot) and :mod:`tests.run.viewer.judge` (what each view shows):

    python -m tests.run.viewer.check out/quickstart/recording.rrd --png viewer.png

(docs/recording.png is made by tools/recording_screenshot.py, which runs the quick start first.)

Exit status: 0 every view drew, 1 a view did not, 3 the viewer or Chromium
could not be run.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2

from tests.run.viewer.browser import ViewerCheckError, screenshot, serve_file
from tests.run.viewer.judge import judge


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("rrd", nargs="?", help="a recording to serve with rerun --serve-web")
    parser.add_argument("--url", help="or: a web viewer URL to open (a live --serve run)")
    parser.add_argument("--png", default="viewer.png", help="where to write the screenshot")
    parser.add_argument("--timeout", type=float, default=240.0, help="seconds to wait, at most")
    args = parser.parse_args(argv)
    if not args.rrd and not args.url:
        parser.error("give a recording or --url")
    try:
        if args.url:
            image = screenshot(args.url, timeout_s=args.timeout)
        else:
            with serve_file(Path(args.rrd)) as url:
                image = screenshot(url, timeout_s=args.timeout)
    except ViewerCheckError as err:
        print(f"viewer_check: error: {err}", file=sys.stderr)
        return 3
    cv2.imwrite(args.png, cv2.cvtColor(image, cv2.COLOR_RGB2BGR))
    verdict = judge(image)
    print(f"wrote {args.png} ({image.shape[1]}x{image.shape[0]})")
    for name, figure in verdict.figures.items():
        print(f"  {name:32s} {figure:g}")
    for problem in verdict.problems:
        print(f"  problem: {problem}")
    return 0 if verdict.ok else 1


if __name__ == "__main__":
    sys.exit(main())
