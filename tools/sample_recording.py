"""Make examples/recording/: a small MCAP recording of the simulated paper head looking at
three markers (as a robot would record it, under its own topic and joint names), the
mapping file that reads it, and the markers' true positions in the head frame.

    python tools/sample_recording.py [DIR]      (default: examples/recording)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from headsim.head.mcap_log import McapRecorder, RecordingHead, Topics
from headsim.head.sim_head import SimHead
from headsim.head.stereo_look import look_and_estimate
from headsim.sim.names import MARKER_COLOURS
from headsim.sim.settings import paper_head
from headsim.sim.simulator import HeadSim

#: The robot's topics and joint names the sample is recorded under.
TOPICS = Topics(
    images=("/left/image_raw", "/right/image_raw"),
    camera_infos=("/left/camera_info", "/right/camera_info"),
    joints={"neck_yaw": "head_pan", "neck_pitch": "head_tilt", "eye": "eyes_verge"},
)
#: The eye poses the head turns to, rad.
POSES = ({"eye": 0.0}, {"eye": 0.04}, {"eye": 0.08}, {"eye": 0.12})

MAPPING = """\
# The mapping for examples/recording/markers.mcap (docs: how-to/real-head).
[topics]
images = ["/left/image_raw", "/right/image_raw"]
camera_infos = ["/left/camera_info", "/right/camera_info"]
joint_states = "/joint_states"

[joints]
neck_yaw = "head_pan"
neck_pitch = "head_tilt"
eye = "eyes_verge"

[head]
baseline_m = 0.15
alpha_e_rad = [{a1!r}, {a2!r}]  # each camera's yaw at eye angle 0 (a calibration's)

[targets]
marker_red = "red"
marker_green = "green"
marker_blue = "blue"
"""


def make(directory: Path) -> Path:
    """Write markers.mcap, mapping.toml and truth.json into ``directory``."""
    directory.mkdir(parents=True, exist_ok=True)
    settings = paper_head()
    with (
        HeadSim("default", settings) as sim,
        McapRecorder(directory / "markers.mcap", TOPICS) as recorder,
    ):
        look_and_estimate(RecordingHead(SimHead(sim), recorder), POSES, MARKER_COLOURS)
        truth = {name: sim.truth.position(name, "head").tolist() for name in MARKER_COLOURS}
    a1, a2 = (camera.mount_yaw_rad for camera in settings.cameras)
    (directory / "mapping.toml").write_text(MAPPING.format(a1=a1, a2=a2))
    (directory / "truth.json").write_text(json.dumps(truth, indent=2) + "\n")
    return directory


if __name__ == "__main__":
    out = make(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("examples/recording"))
    print(
        f"wrote {out}: "
        + ", ".join(f"{p.name} {p.stat().st_size} B" for p in sorted(out.iterdir()))
    )
