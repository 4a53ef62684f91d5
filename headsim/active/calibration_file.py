"""Calibrate once, measure all day: what a head learnt, in a file (``head.json``).

``headsim calibrate SCENARIO --out head.json`` runs a scenario's Sec. V
calibration and writes what the head learnt (initial directions, the extended
fit, standard errors: the results.json ``calibration`` block and the
:class:`HeadKnowledge` built from it) with the head settings it holds for.
A scenario uses it with ``[experiment.calibration] from = "head.json"``
(a path relative to the scenario file's directory) and calibrates no more; a file
made for another head is refused, naming the settings that differ.

The head a calibration holds for is every field of
:class:`~headsim.sim.settings.HeadSettings` except the seed and the cameras'
image noise (they change the images, not the head), flattened to dotted
names (``cam1.kx``) and hashed (SHA-256 of their JSON).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from headsim.active.calibration_report import (
    CalibrationReport,
    CalibrationSource,
    KnowledgeReport,
)
from headsim.active.measurement import HeadKnowledge
from headsim.codec import declared, decode, doc, encode
from headsim.files import to_jsonable, write_json_atomic
from headsim.sim.events import RenderCounts
from headsim.sim.settings import HeadSettings, settings_record

FORMAT = "headsim-calibration/1"
#: Settings that do not change the head a calibration holds for.
NOT_THE_HEAD = ("seed", "noise_std")


class CalibrationFileError(ValueError):
    """A calibration file cannot be used: unreadable, malformed, or for another head."""


def head_fields(settings: HeadSettings) -> dict[str, Any]:
    """The head's settings that a calibration depends on, by dotted name (``cam1.kx``)."""
    flat: dict[str, Any] = {}

    def walk(prefix: str, value: Any) -> None:
        if isinstance(value, dict):
            for key, item in value.items():
                if key not in NOT_THE_HEAD:
                    walk(f"{prefix}{key}.", item)
        else:
            flat[prefix[:-1]] = to_jsonable(value)

    raw = settings_record(settings)  # the cameras' ``extra`` left out while empty
    raw.pop("head", None)
    if not settings.head.is_paper:  # the paper's head is the one every older file was for
        raw["head_model"] = settings.head.name
    cameras = raw.pop("cameras")
    walk("", raw)
    for index, camera in enumerate(cameras):
        walk(f"cam{index + 1}.", camera)
    return dict(sorted(flat.items()))


def head_hash(settings: HeadSettings) -> str:
    """SHA-256 of :func:`head_fields` as canonical JSON."""
    text = json.dumps(head_fields(settings), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True)
class StoredCalibration:
    """A calibration read from a file: what the head knows, and the report of the run
    that found it (no renders of its own; ``source`` says where it came from)."""

    path: Path
    knowledge: HeadKnowledge
    report: CalibrationReport
    scenario: str
    seed: int
    head_hash: str


def knowledge_from_block(block: dict[str, Any]) -> HeadKnowledge:
    """The :class:`HeadKnowledge` of a results.json ``calibration`` block's ``knowledge``."""
    return decode(KnowledgeReport, block["knowledge"]).head_knowledge()


@declared
class CalibrationHead:
    """The head a calibration file holds for."""

    hash: str = doc("SHA-256 of `settings` as JSON (keys sorted, no spaces)")
    settings: dict[str, Any] = doc(
        "every setting of the true head by dotted name (`cam1.kx`), but the seed and the "
        "cameras' image noise (they change the images, not the head); `head_model` for a "
        "head other than the paper's",
        whole=True,
    )


@declared
class CalibrationDocument:
    """A calibration file (``head.json``): its keys in the order written."""

    format: str = doc(f'`"{FORMAT}"`')
    scenario: str = doc("the scenario that calibrated (`told`: a knowledge given, not measured)")
    seed: int = doc("its seed")
    head: CalibrationHead = doc(
        "the head it holds for: a scenario whose head differs is refused, naming each setting"
    )
    calibration: dict[str, Any] = doc(
        "what the head learnt: results.json's `calibration` block (for a knowledge told: "
        "`status`, `targets` 0, `fixated` 0, `positions` and `knowledge` only)",
        whole=True,
    )


def write_calibration(
    path: str | Path,
    settings: HeadSettings,
    learnt: CalibrationReport | HeadKnowledge,
    scenario: str,
    seed: int,
) -> Path:
    """Write what the head ``settings`` learnt: a successful calibration's report, or a
    knowledge told to it (no layout, no fit; it must hold no belief of the head's geometry,
    which the file does not keep)."""
    if isinstance(learnt, HeadKnowledge):
        if learnt.belief is not None:
            raise ValueError("a calibration file holds no belief of the head's geometry")
        told = {"status": "ok", "targets": 0, "fixated": 0, "positions": []}
        block = {**told, "knowledge": encode(KnowledgeReport.of(learnt))}
    elif learnt.knowledge is None:
        raise CalibrationFileError(
            f"calibration did not succeed ({learnt.status_text}): nothing to write"
        )
    else:
        block = encode(learnt)
    path = Path(path)
    head = CalibrationHead(hash=head_hash(settings), settings=head_fields(settings))
    write_json_atomic(path, encode(CalibrationDocument(FORMAT, scenario, seed, head, block)))
    return path


def _differences(stored: dict[str, Any], current: dict[str, Any]) -> list[str]:
    lines = []
    for name in sorted(set(stored) | set(current)):
        a, b = stored.get(name, "absent"), current.get(name, "absent")
        if a != b:
            lines.append(f"{name} (file {a!r}, this head {b!r})")
    return lines


def read_calibration(path: str | Path, settings: HeadSettings) -> StoredCalibration:
    """Read ``path`` and check it holds for the head ``settings`` (else CalibrationFileError)."""
    path = Path(path)
    return calibration_for_head(read_calibration_document(path), path, settings)


def read_calibration_document(path: Path) -> dict[str, Any]:
    """The calibration file ``path`` as JSON, its format checked (else CalibrationFileError)."""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as err:
        raise CalibrationFileError(f"cannot read {path}: {err}") from err
    except json.JSONDecodeError as err:
        raise CalibrationFileError(f"{path} is not JSON: {err}") from err
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise CalibrationFileError(
            f"{path} is not a calibration file (format {FORMAT!r}; write one with "
            "`headsim calibrate SCENARIO --out FILE`)"
        )
    return doc


def calibration_for_head(
    doc: dict[str, Any], path: Path, settings: HeadSettings
) -> StoredCalibration:
    """The calibration file ``doc`` (read from ``path``), checked to hold for the head
    ``settings`` and decoded (else CalibrationFileError)."""
    try:
        head, block = doc["head"], doc["calibration"]
        knowledge = knowledge_from_block(block)
        stored_fields, stored_hash = dict(head["settings"]), str(head["hash"])
    except (KeyError, TypeError, ValueError) as err:
        raise CalibrationFileError(f"{path} is malformed: {err!r} missing or wrong") from err
    if stored_hash != head_hash(settings):
        differ = _differences(stored_fields, head_fields(settings))
        detail = "; ".join(differ) if differ else "its settings were edited after it was written"
        raise CalibrationFileError(
            f"{path} was made for a different head: {detail}. Calibrate this head with "
            "`headsim calibrate SCENARIO --out FILE`"
        )
    try:
        counts = block.get("render_counts")  # none in a file from before previews counted
        source = CalibrationSource(
            path=str(path),
            scenario=str(doc.get("scenario", "")),
            seed=int(doc.get("seed", 0)),
            head_hash=stored_hash,
            render_counts=None if counts is None else decode(RenderCounts, counts),
        )
        report = decode(CalibrationReport, block, renders=RenderCounts(), source=source)
    except (KeyError, TypeError, ValueError) as err:
        raise CalibrationFileError(f"{path} is malformed: {err!r} missing or wrong") from err
    return StoredCalibration(
        path=path,
        knowledge=knowledge,
        report=report,
        scenario=source.scenario,
        seed=source.seed,
        head_hash=stored_hash,
    )
