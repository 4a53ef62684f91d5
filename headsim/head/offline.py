"""Estimates from any head's recording (``headsim estimate LOG.mcap --mapping MAP.toml``).

The mapping file says where the recording keeps each stream and what the head is:

.. code-block:: toml

    [topics]                      # defaults: headsim's own topics
    images = ["/left/image_raw", "/right/image_raw"]          # Ca1 (left), Ca2 (right)
    camera_infos = ["/left/camera_info", "/right/camera_info"]
    joint_states = "/joint_states"

    [joints]                      # headsim's joint = the robot's name (eye2: independent eyes)
    eye = "l_eye_pan"
    eye2 = "r_eye_pan"

    [signs]                       # robot angle x sign = headsim's angle (positive inward)
    eye2 = -1.0

    [head]                        # what the head believes of itself
    baseline_m = 0.15
    alpha_e_rad = [0.0, 0.0]      # each eye's initial direction, from a calibration

    [targets]                     # what to find: name = marker colour
    ball = "red"

Each stereo pair (Ca1's image with Ca2's nearest in time), with the joints
interpolated to its time, gives a triangulation of every target found in both
images (:func:`~headsim.head.stereo_look.estimate_markers`); a target's estimate is
the median of its pairs'.  With ``--truth`` (a JSON object: name -> [x, y, z] in the
head frame, m) each estimate is scored.  results.json is in the run's schema
(:func:`headsim.runs.serialise.estimate_payload`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from headsim.errors import BadInput
from headsim.head.interface import JointReading
from headsim.head.mcap_log import HeadLog, Topics, read_log
from headsim.head.replay import pair_by_stamp
from headsim.head.stereo_look import StereoEstimate, estimate_markers
from headsim.sim.settings import HeadBelief
from headsim.vision.markers import COLOURS

#: Each mapping table's keys.
_KEYS = {
    "topics": ("images", "camera_infos", "joint_states", "tf", "estimates"),
    "joints": ("neck_yaw", "neck_pitch", "eye", "eye2"),
    "signs": ("neck_yaw", "neck_pitch", "eye", "eye2"),
    "head": ("baseline_m", "alpha_e_rad", "nodal_offset_m", "side_offset_m"),
    "targets": None,
}


class MappingError(BadInput, ValueError):
    """A mapping file headsim cannot use: the message names the key and what is allowed."""


@dataclass(frozen=True)
class LogMapping:
    """A mapping file, read: topics and joint names, signs, belief, initial directions, targets."""

    topics: Topics
    belief: HeadBelief
    alpha_e_rad: tuple[float, float]
    targets: Mapping[str, str]


def _pair(value: Any, key: str, kind: type) -> tuple[Any, Any]:
    if not (
        isinstance(value, list) and len(value) == 2 and all(isinstance(v, kind) for v in value)
    ):
        raise MappingError(
            f"{key} must be a list of two {kind.__name__}s (Ca1's, Ca2's), got {value!r}"
        )
    return value[0], value[1]


def _number(value: Any, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise MappingError(f"{key} must be a finite number, got {value!r}")
    return float(value)


def read_mapping(path: str | Path) -> LogMapping:
    """Read and check a mapping file (TOML)."""
    import tomllib

    try:
        document = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as err:
        raise MappingError(f"--mapping: cannot read {path}: {err.strerror or err}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise MappingError(f"--mapping: {path} is not TOML: {err}".splitlines()[0]) from None
    for table, value in document.items():
        if table not in _KEYS:
            raise MappingError(f"{path}: unknown table [{table}]; allowed: {', '.join(_KEYS)}")
        if not isinstance(value, dict):
            raise MappingError(f"{path}: {table} must be a table")
        allowed = _KEYS[table]
        for key in value:
            if allowed is not None and key not in allowed:
                raise MappingError(
                    f"{path}: unknown key {table}.{key}; allowed: {', '.join(allowed)}"
                )
    topics_table = document.get("topics", {})
    joints = document.get("joints", {})
    for key, name in joints.items():
        if not isinstance(name, str) or not name:
            raise MappingError(f"joints.{key} must be the robot's joint name, got {name!r}")
    fields: dict[str, Any] = {"joints": dict(joints)}
    for key in ("images", "camera_infos"):
        if key in topics_table:
            fields[key] = _pair(topics_table[key], f"topics.{key}", str)
    for key in ("joint_states", "tf", "estimates"):
        if key in topics_table:
            if not isinstance(topics_table[key], str):
                raise MappingError(f"topics.{key} must be a topic name, got {topics_table[key]!r}")
            fields[key] = topics_table[key]
    signs = {}
    for key, sign in document.get("signs", {}).items():
        if sign not in (1, -1, 1.0, -1.0) or isinstance(sign, bool):
            raise MappingError(f"signs.{key} must be 1 or -1, got {sign!r}")
        signs[key] = float(sign)
    head = document.get("head", {})
    belief = HeadBelief()
    changes: dict[str, Any] = {}
    if "baseline_m" in head:
        changes["baseline_m"] = _number(head["baseline_m"], "head.baseline_m")
    for key in ("nodal_offset_m", "side_offset_m"):
        if key in head:
            pair = _pair(head[key], f"head.{key}", float)
            changes[key] = (_number(pair[0], f"head.{key}"), _number(pair[1], f"head.{key}"))
    try:
        belief = replace(belief, **changes)
    except ValueError as err:
        raise MappingError(f"head: {err}") from None
    alpha = (0.0, 0.0)
    if "alpha_e_rad" in head:
        a = _pair(head["alpha_e_rad"], "head.alpha_e_rad", float)
        alpha = (_number(a[0], "head.alpha_e_rad"), _number(a[1], "head.alpha_e_rad"))
    targets = document.get("targets", {})
    if not targets:
        raise MappingError(f"{path}: [targets] must name at least one target (name = colour)")
    for name, colour in targets.items():
        if colour not in COLOURS:
            raise MappingError(
                f"targets.{name} must be a marker colour ({', '.join(COLOURS)}), got {colour!r}"
            )
    return LogMapping(Topics(**fields, signs=signs), belief, alpha, dict(targets))


@dataclass(frozen=True)
class TargetEstimate:
    """A target's estimate over a recording: the median of its ``pairs`` triangulations
    (NaN when no pair found it in both images), in H, m."""

    name: str
    point_head_m: np.ndarray
    pairs: int
    seen: int


def estimate_log(log: HeadLog, mapping: LogMapping) -> tuple[list[TargetEstimate], int]:
    """Every target's estimate from every stereo pair of ``log``; and the pairs used."""
    pairs = pair_by_stamp(*log.images)
    per_target: dict[str, list[StereoEstimate]] = {name: [] for name in mapping.targets}
    for frame in pairs:
        reading = JointReading(frame.time_s, dict(log.joints.at(frame.time_s)), {})
        for estimate in estimate_markers(
            frame, reading, mapping.belief, mapping.targets, mapping.alpha_e_rad
        ):
            per_target[estimate.name].append(estimate)
    out = []
    for name, found in per_target.items():
        ok = [e.point_head_m for e in found if e.status == "ok"]
        point = np.median(np.array(ok), axis=0) if ok else np.full(3, np.nan)
        out.append(TargetEstimate(name, point, len(ok), len(found)))
    return out, len(pairs)


def read_truth(path: str | Path) -> dict[str, np.ndarray]:
    """A truth file: a JSON object, target name -> [x, y, z] in the head frame, m."""
    try:
        document = json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as err:
        raise BadInput(f"--truth: cannot read {path}: {err.strerror or err}") from None
    except ValueError as err:
        raise BadInput(f"--truth: {path} is not JSON: {err}") from None
    if not isinstance(document, dict):
        raise BadInput(f"--truth: {path} must be a JSON object of name -> [x, y, z]")
    truth = {}
    for name, point in document.items():
        if not (isinstance(point, list) and len(point) == 3):
            raise BadInput(f"--truth: {name} must be [x, y, z] in the head frame, m")
        truth[name] = np.array([_number(v, f"truth {name}") for v in point])
    return truth


def estimate_file(
    log_path: str | Path, mapping_path: str | Path
) -> tuple[LogMapping, list[TargetEstimate], int]:
    """A recording estimated as its mapping says: the mapping, each target's estimate and
    the stereo pairs used (``headsim estimate``; results.json is
    :func:`headsim.runs.serialise.estimate_payload`'s)."""
    mapping = read_mapping(mapping_path)
    log = read_log(log_path, mapping.topics)
    estimates, pairs = estimate_log(log, mapping)
    return mapping, estimates, pairs


__all__ = [
    "MappingError",
    "TargetEstimate",
    "estimate_file",
    "estimate_log",
    "read_mapping",
    "read_truth",
]
