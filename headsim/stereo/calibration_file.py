"""A :class:`StereoCalibration` as a JSON file: made once, then told to a run
(``[experiment.stereo] from``) that triangulates with it instead of calibrating.

Every array is written as nested lists of floats (``repr`` round-trips each
float exactly), so a calibration read back triangulates exactly as the one written;
the layout is :class:`StereoCalibration`'s declaration (:mod:`headsim.codec`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from headsim.codec import decode, encode
from headsim.files import write_json_atomic
from headsim.stereo.calibration import StereoCalibration

#: The file's ``format`` and ``version``.
FORMAT = "headsim-stereo-calibration"
VERSION = 1


class StereoCalibrationFileError(ValueError):
    """A stereo calibration file that cannot be read: the message says why, in one line."""


def stereo_calibration_document(calibration: StereoCalibration) -> dict[str, Any]:
    """The file's JSON document for ``calibration``."""
    return {"format": FORMAT, "version": VERSION, **encode(calibration)}


def write_stereo_calibration(path: Path, calibration: StereoCalibration) -> Path:
    """Write ``calibration`` to ``path`` (JSON); returns ``path``."""
    write_json_atomic(path, stereo_calibration_document(calibration))
    return path


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
        return decode(StereoCalibration, doc)
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
