"""A study's experiment through the runner: its head as a preset, and what the head is told.

A study states its experiment as scenario tables
(:func:`headsim.scenario.loading.scenario_from_document`) and runs it with
:func:`headsim.runs.runner.run_scenario`.  What the head already knows (a
calibration the study made) reaches the run the way a user's does: as a
calibration file that the scenario names (``experiment.calibration.from``).
"""

from __future__ import annotations

from contextlib import suppress
from dataclasses import asdict
from pathlib import Path
from typing import Any

from headsim.active.calibration_file import knowledge_from_block, write_calibration
from headsim.active.calibration_report import CalibrationReport
from headsim.active.measurement import HeadKnowledge
from headsim.active.principal import PrincipalPointRun
from headsim.procedures.stereo import StereoResult
from headsim.procedures.zoom_fixed_points import ZoomFixedPoints
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import scenario_from_document
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.sim.settings import PRESETS, HeadSettings


def preset_of(settings: HeadSettings) -> str:
    """The name of the preset whose head is ``settings`` (ValueError if none is)."""
    for name, make in PRESETS.items():
        if make(seed=settings.seed) == settings:
            return name
    raise ValueError(
        "the head is no preset's: describe it in the scenario's [head], [cam1] and [cam2]"
    )


#: Each camera's keys of ``[cam1]``/``[cam2]`` (:class:`CameraSettings` fields of the same name).
_CAMERA_KEYS = (
    "width",
    "height",
    "kx",
    "ky",
    "cx",
    "cy",
    "k1",
    "k2",
    "noise_std",
    "nodal_offset_m",
    "side_offset_m",
    "eye_axis_tilt_rad",
)


def head_document(settings: HeadSettings) -> dict[str, Any]:
    """The scenario tables ``[head]``, ``[cam1]``, ``[cam2]`` (and ``seed``) of the ideal
    head with the cameras of ``settings``: every camera key given, the mount yaws, pitches
    and rolls.  :func:`scenario_with_head` checks that the scenario's head is ``settings``."""
    cams = settings.cameras
    doc: dict[str, Any] = {
        "seed": settings.seed,
        "head": {
            "preset": "ideal",
            "mount_yaw_rad": [c.mount_yaw_rad for c in cams],
            "mount_pitch_rad": [c.mount_pitch_rad for c in cams],
            "mount_roll_rad": [c.mount_roll_rad for c in cams],
        },
    }
    for key, cam in zip(names.CAMERAS, cams, strict=True):
        values = {k: getattr(cam, k) for k in _CAMERA_KEYS}
        doc[key] = {k: v for k, v in values.items() if v is not None}
    return doc


def scenario_with_head(doc: dict[str, Any], name: str, settings: HeadSettings) -> Scenario:
    """The scenario ``doc`` (without its head's tables) on the head ``settings``, told by
    :func:`head_document` where only its cameras differ from the ideal head's, else (a
    head built off its design) as its preset (ValueError if the scenario's head came out
    otherwise)."""
    head = head_document(settings)
    if HeadSettings(seed=settings.seed, cameras=settings.cameras) != settings:
        with suppress(ValueError):  # no preset's either: refused below
            head = {"seed": settings.seed, "head": {"preset": preset_of(settings)}}
    scenario = scenario_from_document({**doc, **head}, name)
    if scenario.settings != settings:
        raise ValueError("the head has settings that [head], [cam1] and [cam2] cannot state")
    return scenario


def knowledge_file(path: Path, settings: HeadSettings, knowledge: HeadKnowledge) -> Path:
    """Write a calibration file at ``path`` telling the head ``settings`` ``knowledge``.

    The file holds the knowledge alone (no ball layout, no fit): what
    ``experiment.calibration.from`` reads.  A knowledge with its own ``belief``
    cannot be written (the file holds no head geometry).
    """
    return write_calibration(path, settings, knowledge, "told", settings.seed)


def calibration_run(
    settings: HeadSettings,
    positions_world_m: Any,
    goal_columns_px: tuple[float, float] | None = None,
    **keys: Any,
) -> tuple[HeadKnowledge, CalibrationReport]:
    """Sec. V on the head ``settings`` with the ball at ``positions_world_m`` ((N, 3), W,
    m), through the runner, the servo on ``goal_columns_px`` (None: the image centres);
    ``keys``: more ``[experiment.calibration]`` keys.  Returns what the head learnt and
    the report (ValueError if the calibration failed)."""
    calibration = {"positions_world_m": [[float(c) for c in p] for p in positions_world_m]}
    experiment: dict[str, Any] = {
        "procedure": "calibration",
        "calibration": {**calibration, **keys},
    }
    if goal_columns_px is not None:
        experiment["goal_columns_px"] = [float(u) for u in goal_columns_px]
    doc = {"description": "Sec. V on a study's ball layout", "experiment": experiment}
    result = run_scenario(scenario_with_head(doc, "study_calibration", settings))
    report = result.calibration
    if not result.ok or report is None or report.knowledge is None:
        raise ValueError(f"study calibration failed: {'; '.join(result.failures)}")
    return knowledge_from_block({"knowledge": asdict(report.knowledge)}), report


def zoom_fixed_points_run(
    settings: HeadSettings, zoom: float, poses: int, board_seed: int
) -> PrincipalPointRun:
    """The zoom fixed points of the head ``settings`` at ``zoom``, from ``poses`` board
    poses drawn from ``default_rng(board_seed)``, through the runner (ValueError if
    they could not be found)."""
    experiment = {
        "procedure": "zoom_fixed_points",
        "zoom_fixed_points": {"zoom": zoom, "poses": poses, "board_seed": board_seed},
    }
    doc = {"description": "a study's zoom fixed points", "experiment": experiment}
    result = run_scenario(scenario_with_head(doc, "study_zoom_fixed_points", settings))
    found = result.experiment
    if not result.ok or not isinstance(found, ZoomFixedPoints):
        raise ValueError(f"study zoom fixed points failed: {'; '.join(result.failures)}")
    return found.run


def zhang_run(
    settings: HeadSettings, poses: int, distance_m: tuple[float, float], board_seed: int
) -> StereoResult:
    """Zhang's calibration of the head ``settings``' pair from ``poses`` board poses drawn
    from ``default_rng(board_seed)`` at ``distance_m`` from camera 1 (m), each board found
    through a window, through the runner; the result carries the calibration (ValueError
    if too few views showed the board)."""
    stereo = {
        "views": poses,
        "distance_m": [float(d) for d in distance_m],
        "board_seed": board_seed,
        "board_look": "windowed",
    }
    doc = {
        "description": "a study's Zhang calibration",
        "experiment": {"procedure": "stereo", "stereo": stereo},
    }
    result = run_scenario(scenario_with_head(doc, "study_zhang", settings))
    calibrated = result.experiment
    if not isinstance(calibrated, StereoResult) or calibrated.calibration is None:
        raise ValueError(f"study Zhang calibration failed: {'; '.join(result.failures)}")
    return calibrated


__all__ = [
    "calibration_run",
    "head_document",
    "knowledge_file",
    "preset_of",
    "scenario_with_head",
    "zhang_run",
    "zoom_fixed_points_run",
]
