"""A procedure on the :class:`~headsim.head.interface.Head` interface alone: turn the eyes
to each of a list of poses, read the joints, grab a stereo pair, find coloured markers
in both images and triangulate each in the head frame.

It reads images, encoders, the cameras as the head believes them (CameraInfo) and its
believed geometry: nothing else, so it runs the same on a simulator, a recording
(:class:`~headsim.head.replay.ReplayHead`) or a robot.  Triangulation is pure math:
:func:`triangulate_rays`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from headsim.geometry.camera_model import UndistortionError
from headsim.head.camera_info import pinhole_of
from headsim.head.interface import Head, JointReading, StereoFrame
from headsim.head.mcap_log import believed_head_from_cameras
from headsim.sim.settings import HeadBelief
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import find_marker


@dataclass(frozen=True)
class StereoEstimate:
    """One marker triangulated from one stereo pair.

    ``point_head_m``: the midpoint of the two rays' closest approach, in H, m (NaN when
    not found); ``ray_gap_m``: how far the rays miss each other, m; ``uv_px``: the
    marker's pixel in each image (None: not found); ``status``: "ok" or why not.
    """

    name: str
    time_s: float
    point_head_m: np.ndarray
    ray_gap_m: float
    uv_px: tuple[tuple[float, float] | None, tuple[float, float] | None]
    status: str


def triangulate_rays(
    origins: Sequence[np.ndarray], directions: Sequence[np.ndarray]
) -> tuple[np.ndarray, float]:
    """The midpoint of the closest approach of two rays, and their gap, m.  Raises
    ValueError for parallel rays (no depth)."""
    o1, o2 = (np.asarray(o, dtype=float) for o in origins)
    d1, d2 = (np.asarray(d, dtype=float) / np.linalg.norm(d) for d in directions)
    w = o1 - o2
    b = float(d1 @ d2)
    denominator = 1.0 - b * b
    if denominator < 1e-12:
        raise ValueError("the rays are parallel: no depth")
    s = (b * float(d2 @ w) - float(d1 @ w)) / denominator
    t = (float(d2 @ w) - b * float(d1 @ w)) / denominator
    p1, p2 = o1 + s * d1, o2 + t * d2
    return (p1 + p2) / 2, float(np.linalg.norm(p1 - p2))


def estimate_markers(
    frame: StereoFrame,
    reading: JointReading,
    belief: HeadBelief,
    colours: Mapping[str, str],
    alpha_e_rad: tuple[float, float] = (0.0, 0.0),
) -> list[StereoEstimate]:
    """Each marker (name -> colour) found in both images of ``frame`` and triangulated with
    the eyes at ``reading``'s angles (:func:`believed_head_from_cameras`)."""
    poses = believed_head_from_cameras(belief, reading.positions_rad, alpha_e_rad)
    lenses = (pinhole_of(frame.left.camera_info), pinhole_of(frame.right.camera_info))
    out = []
    for name, colour in colours.items():
        found = [find_marker(image.image, colour) for image in (frame.left, frame.right)]
        uvs = tuple(
            None
            if d.uv is None or d.status is not DetectionStatus.FOUND
            else (float(d.uv[0]), float(d.uv[1]))
            for d in found
        )
        nan = np.full(3, np.nan)
        if uvs[0] is None or uvs[1] is None:
            missing = " and ".join(f"cam{i + 1}" for i, uv in enumerate(uvs) if uv is None)
            out.append(
                StereoEstimate(
                    name, frame.time_s, nan, np.nan, (uvs[0], uvs[1]), f"not found in {missing}"
                )
            )
            continue
        try:
            rays = [
                pose[:3, :3] @ np.array([*lens.normalise(np.array(uv)), 1.0])
                for pose, lens, uv in zip(poses, lenses, (uvs[0], uvs[1]), strict=True)
            ]
            point, gap = triangulate_rays([poses[0][:3, 3], poses[1][:3, 3]], rays)
        except (UndistortionError, ValueError) as err:
            out.append(StereoEstimate(name, frame.time_s, nan, np.nan, (uvs[0], uvs[1]), str(err)))
            continue
        out.append(StereoEstimate(name, frame.time_s, point, gap, (uvs[0], uvs[1]), "ok"))
    return out


def look_and_estimate(
    head: Head,
    poses: Sequence[Mapping[str, float]],
    colours: Mapping[str, str],
    alpha_e_rad: tuple[float, float] = (0.0, 0.0),
) -> list[StereoEstimate]:
    """At each pose (joint -> rad): command it, read the joints, grab a pair, estimate."""
    out: list[StereoEstimate] = []
    for pose in poses:
        head.command_position(pose)
        reading = head.read_joints()
        frame = head.grab_stereo()
        out.extend(estimate_markers(frame, reading, head.belief, colours, alpha_e_rad))
    return out


__all__ = ["StereoEstimate", "estimate_markers", "look_and_estimate", "triangulate_rays"]
