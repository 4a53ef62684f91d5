"""A :class:`StereoCalibration` as a JSON file: made once, then told to a run
(``[experiment.stereo] from``) that triangulates with it instead of calibrating.

Every array is written as nested lists of floats (``repr`` round-trips each
float exactly), so a calibration read back triangulates exactly as the one written.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from headsim.files import write_json_atomic
from headsim.stereo.calibration import CameraCalibration, StereoCalibration

#: The file's ``format`` and ``version``.
FORMAT = "headsim-stereo-calibration"
VERSION = 1

_CAMERAS = ("mono1", "mono2", "cam1", "cam2")
_MATRICES = ("cam2_from_cam1", "true_cam2_from_cam1", "true_head_from_cam1")


class StereoCalibrationFileError(ValueError):
    """A stereo calibration file that cannot be read: the message says why, in one line."""


def _camera_block(camera: CameraCalibration) -> dict[str, Any]:
    return {
        "K": camera.K.tolist(),
        "dist": camera.dist.tolist(),
        "rms_px": camera.rms_px,
        "true_K": camera.true_K.tolist(),
        "true_dist": camera.true_dist.tolist(),
        "image_size": list(camera.image_size),
    }


def stereo_calibration_document(calibration: StereoCalibration) -> dict[str, Any]:
    """The file's JSON document for ``calibration``."""
    return {
        "format": FORMAT,
        "version": VERSION,
        **{key: _camera_block(getattr(calibration, key)) for key in _CAMERAS},
        "stereo_rms_px": calibration.stereo_rms_px,
        **{key: getattr(calibration, key).tolist() for key in _MATRICES},
        "views": calibration.views,
        "refined": calibration.refined,
    }


def write_stereo_calibration(path: Path, calibration: StereoCalibration) -> Path:
    """Write ``calibration`` to ``path`` (JSON); returns ``path``."""
    write_json_atomic(path, stereo_calibration_document(calibration))
    return path


def _matrix(value: Any, shape: tuple[int, ...]) -> np.ndarray:
    array = np.array(value, dtype=float)
    if array.shape != shape or not np.all(np.isfinite(array)):
        raise ValueError(f"not {' x '.join(map(str, shape))} finite numbers")
    return array


def _camera(block: dict[str, Any]) -> CameraCalibration:
    width, height = (int(v) for v in block["image_size"])
    return CameraCalibration(
        K=_matrix(block["K"], (3, 3)),
        dist=_matrix(block["dist"], (5,)),
        rms_px=float(block["rms_px"]),
        true_K=_matrix(block["true_K"], (3, 3)),
        true_dist=_matrix(block["true_dist"], (5,)),
        image_size=(width, height),
    )


def read_stereo_calibration(path: str | Path) -> StereoCalibration:
    """The calibration in the file ``path`` (else :class:`StereoCalibrationFileError`)."""
    path = Path(path)
    try:
        doc = json.loads(path.read_text())
    except OSError as err:
        raise StereoCalibrationFileError(f"cannot read {path}: {err.strerror}") from err
    except json.JSONDecodeError as err:
        raise StereoCalibrationFileError(f"{path} is not JSON: {err}") from err
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise StereoCalibrationFileError(f"{path} is not a {FORMAT} file")
    if doc.get("version") != VERSION:
        raise StereoCalibrationFileError(
            f"{path} has version {doc.get('version')!r}; this headsim reads {VERSION}"
        )
    try:
        cameras = [_camera(doc[key]) for key in _CAMERAS]
        matrices = [_matrix(doc[key], (4, 4)) for key in _MATRICES]
        return StereoCalibration(
            mono1=cameras[0],
            mono2=cameras[1],
            cam1=cameras[2],
            cam2=cameras[3],
            stereo_rms_px=float(doc["stereo_rms_px"]),
            cam2_from_cam1=matrices[0],
            true_cam2_from_cam1=matrices[1],
            true_head_from_cam1=matrices[2],
            views=int(doc["views"]),
            refined=bool(doc["refined"]),
        )
    except (KeyError, TypeError, ValueError) as err:
        raise StereoCalibrationFileError(f"{path} is malformed: {err!s}") from err


__all__ = [
    "FORMAT",
    "VERSION",
    "StereoCalibrationFileError",
    "read_stereo_calibration",
    "stereo_calibration_document",
    "write_stereo_calibration",
]
