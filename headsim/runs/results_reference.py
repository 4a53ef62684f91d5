"""What each key of results.json means, read from its declared types: the reference page's source.

:data:`RESULTS_FIELDS` maps a key's path to its meaning (:func:`headsim.codec.describe`
of :class:`~headsim.runs.serialise.ResultsDocument`): ``a.b`` a key of a
table, ``a[].b`` a key of each entry of a list, ``a.*`` each key of a table
whose keys are data (a knowledge, a phase).  A path listed without any of its
children is described as a whole (its keys are not listed one by one).
:data:`CALIBRATION_FILE_FIELDS` does the same for a calibration file.
:func:`experiment_fields` gives each procedure's ``experiment`` keys the same
way, relative to ``experiment``, from its declaration (``Procedure.results``).
:func:`undocumented` and :func:`documented_paths` compare a real results.json
with both; the documentation hook (``tools/docs_pages.py``) writes the page
from them.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

from headsim.active.calibration_file import CalibrationDocument
from headsim.codec import describe
from headsim.procedures.contract import procedures
from headsim.runs.outcomes import SurfaceResult
from headsim.runs.serialise import ResultsDocument

#: Every key of results.json outside ``experiment``'s procedure keys, in the order written:
#: read from the declarations of the document's types.
RESULTS_FIELDS: dict[str, str] = describe(ResultsDocument)

#: Every key of a calibration file (``headsim calibrate``'s ``head.json``), in the order written.
CALIBRATION_FILE_FIELDS: dict[str, str] = describe(CalibrationDocument)

#: ``experiment`` keys a procedure writes only when it failed.
FAILED_ONLY = frozenset({"reason"})

#: ``experiment`` keys written only with markerless targets (``[scene.room] targets``).
MARKERLESS_ONLY = frozenset(describe(SurfaceResult))


def experiment_fields() -> dict[str, dict[str, str]]:
    """Each procedure's ``experiment`` keys beside ``procedure``, relative to ``experiment``:
    its declaration's ``results``, in the registry's order."""
    return {p.name: dict(p.results) for p in procedures()}


def _child(fields: Mapping[str, str], parent: str, key: str) -> str | None:
    """The documented path of ``key`` under ``parent`` (a listed key, else ``parent.*``)."""
    named = f"{parent}.{key}" if parent else key
    if named in fields:
        return named
    wildcard = f"{parent}.*"
    return wildcard if parent and wildcard in fields else None


def _opens(fields: Mapping[str, str], path: str) -> bool:
    """Whether ``path``'s keys are listed one by one."""
    return any(p.startswith((f"{path}.", f"{path}[]")) for p in fields)


def _walk(value: Any, path: str, fields: Mapping[str, str]) -> Iterator[tuple[str, str | None]]:
    """(path, documented path or None) of every key in a table whose keys are listed."""
    if isinstance(value, list):
        for item in value:
            yield from _walk(item, f"{path}[]", fields)
        return
    if not isinstance(value, dict) or not (path == "" or _opens(fields, path)):
        return
    for key, item in value.items():
        found = f"{path}.{key}" if path else key
        documented = _child(fields, path, key)
        yield found, documented
        if documented is not None:
            yield from _walk(item, documented, fields)


def _experiment_fields(results: Mapping[str, Any]) -> dict[str, str]:
    procedure = results.get("experiment", {}).get("procedure")
    return {f"experiment.{k}": v for k, v in experiment_fields().get(procedure, {}).items()}


def _pairs(results: Mapping[str, Any]) -> list[tuple[str, str | None]]:
    fields = {**RESULTS_FIELDS, **_experiment_fields(results)}
    return list(_walk(dict(results), "", fields))


def undocumented(results: Mapping[str, Any]) -> list[str]:
    """Keys of a results.json document that have no meaning here, as paths of the reference."""
    return sorted({raw for raw, documented in _pairs(results) if documented is None})


def documented_paths(results: Mapping[str, Any]) -> set[str]:
    """The documented paths a results.json document holds."""
    return {documented for _, documented in _pairs(results) if documented is not None}


__all__ = [
    "CALIBRATION_FILE_FIELDS",
    "FAILED_ONLY",
    "MARKERLESS_ONLY",
    "RESULTS_FIELDS",
    "documented_paths",
    "experiment_fields",
    "undocumented",
]
