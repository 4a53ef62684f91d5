"""A result type declared once: each dataclass field's meaning, unit and JSON key in its metadata.

A field declared with :func:`doc` carries its meaning (the unit is in its name or its
meaning) and, where the file's layout asks, its JSON key, when it is written and how.
From that one declaration come the JSON (:func:`encode`), reading it back
(:func:`decode`) and the reference pages (:func:`describe`): results.json, head.json
and the stereo calibration file are written, read and documented from their types.

Plain dataclass metadata, not pydantic or cattrs: the core already returns frozen
dataclasses (NumPy arrays in them), their bytes on disk must not move, and importing
this costs nothing beyond the standard library.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import types
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T")

_KEY = "headsim.codec"


@dataclass(frozen=True)
class Declared:
    """What :func:`doc` puts in a field's metadata.

    ``key``: its JSON key (dots nest it: ``std_errors.offset_m``; None: the field's
    name); ``skip``: not written (another field's ``read`` sets it); ``omit_if_none``:
    left out while None; ``only_with``: written only while that field is not None;
    ``write(obj)``: the value written, from the whole object; ``read(value)``: the
    fields that value sets; ``parts``: the meanings of a table's keys whose type is
    not declared here (relative paths, as :func:`describe` gives them); ``each``: the
    meaning of each key of a table whose keys are data (``dict[str, X]``); ``shape``:
    an array's shape, checked (with finiteness) when read; ``flat``: a declared type's
    keys written (and described) beside the field's own, not in a table of their own.
    """

    meaning: str
    key: str | None = None
    skip: bool = False
    omit_if_none: bool = False
    only_with: str | None = None
    write: Callable[[Any], Any] | None = None
    read: Callable[[Any], Mapping[str, Any]] | None = None
    parts: Mapping[str, str] = dataclasses.field(default_factory=dict)
    each: str | None = None
    shape: tuple[int, ...] | None = None
    whole: bool = False
    flat: bool = False


def doc(
    meaning: str,
    *,
    default: Any = dataclasses.MISSING,
    default_factory: Any = dataclasses.MISSING,
    init: bool = True,
    compare: bool = True,
    repr: bool = True,
    **declared: Any,
) -> Any:
    """A dataclass field with its meaning (and :class:`Declared`'s other keywords)."""
    return dataclasses.field(
        default=default,
        default_factory=default_factory,
        init=init,
        compare=compare,
        repr=repr,
        metadata={_KEY: Declared(meaning, **declared)},
    )


@typing.dataclass_transform(frozen_default=True, field_specifiers=(dataclasses.field, doc))
def declared(cls: type[T]) -> type[T]:
    """A frozen dataclass whose fields may be declared with :func:`doc` (the type checker
    then sees each field's default, or its lack, as for ``dataclasses.field``)."""
    return dataclass(frozen=True)(cls)


def declaration(f: dataclasses.Field[Any]) -> Declared:
    """A field's declaration (a field declared without :func:`doc` has no meaning)."""
    found = f.metadata.get(_KEY)
    return found if isinstance(found, Declared) else Declared("")


_HINTS: dict[type, dict[str, Any]] = {}


def _hints(cls: type) -> dict[str, Any]:
    """A declared type's field types, resolved once."""
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls)
    return _HINTS[cls]


def keys(cls: type) -> tuple[str, ...]:
    """The top-level JSON keys of ``cls``, in the order written."""
    out: dict[str, None] = {}
    for f in dataclasses.fields(cls):
        d = declaration(f)
        inner = _inner(_hints(cls)[f.name])[0] if d.flat else None
        if inner is not None:
            out.update(dict.fromkeys(keys(inner)))
        elif not d.skip:
            out[(d.key or f.name).split(".")[0]] = None
    return tuple(out)


# -- writing ------------------------------------------------------------------------------


def encode(value: Any) -> Any:
    """``value`` as plain data: a dataclass as a table of its declared keys in field order,
    an enum as its value, a tuple as a list; arrays and floats stay as they are (the
    JSON writer, :func:`headsim.files.to_jsonable`, makes NaN null)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return _encode_fields(value)
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, (list, tuple)):
        return [encode(v) for v in value]
    if isinstance(value, dict):
        return {k: encode(v) for k, v in value.items()}
    return value


def _encode_fields(obj: Any) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for f in dataclasses.fields(obj):
        d = declaration(f)
        if d.skip or (d.only_with is not None and getattr(obj, d.only_with) is None):
            continue
        value = getattr(obj, f.name)
        if d.omit_if_none and value is None:
            continue
        table, *inner = (d.key or f.name).split(".")
        written = encode(d.write(obj) if d.write is not None else value)
        if d.flat:
            out.update(written)
        elif inner:
            out.setdefault(table, {})[".".join(inner)] = written
        else:
            out[table] = written
    return out


# -- reading ------------------------------------------------------------------------------


def decode(cls: type[T], data: Mapping[str, Any], **given: Any) -> T:
    """The ``cls`` that :func:`encode` wrote as ``data`` (``given``: fields set instead of
    read).  A missing key whose field has no default raises KeyError naming its path; a
    value of the wrong kind TypeError, an array of the wrong shape ValueError."""
    return _decode(cls, data, "", given)


def _decode(cls: type[T], data: Any, path: str, given: Mapping[str, Any]) -> T:
    if not isinstance(data, Mapping):
        raise TypeError(f"{path or cls.__name__}: a table expected, got {data!r}")
    hints = _hints(cls)
    values: dict[str, Any] = {}
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        d = declaration(f)
        if not f.init or f.name in given or f.name in values or d.skip:
            continue
        key = d.key or f.name
        if d.flat:
            inner, _ = _inner(hints[f.name])
            if inner is not None and _keys_held(inner, data):
                values[f.name] = _decode(inner, data, path, {})
            continue
        found, raw = _lookup(data, key)
        if not found:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise KeyError(f"{path}{key}")
            continue
        if d.read is not None:
            values.update(d.read(raw))
        else:
            values[f.name] = _value(hints[f.name], raw, f"{path}{key}", d.shape)
    return cls(**values, **given)


def _keys_held(cls: type, data: Mapping[str, Any]) -> bool:
    """Whether ``data`` holds any of the keys ``cls`` writes."""
    return any(k in data for k in keys(cls))


def _lookup(data: Mapping[str, Any], key: str) -> tuple[bool, Any]:
    value: Any = data
    for part in key.split("."):
        if not isinstance(value, Mapping) or part not in value:
            return False, None
        value = value[part]
    return True, value


def _value(hint: Any, raw: Any, key: str, shape: tuple[int, ...] | None = None) -> Any:
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        if raw is None and type(None) in args:
            return None
        members = [a for a in args if a is not type(None)]
        return _value(members[0], raw, key, shape) if len(members) == 1 else raw
    if hint is Any:
        return raw
    if hint is np.ndarray:
        array = np.array(raw, dtype=float)
        if shape is not None and (array.shape != shape or not np.all(np.isfinite(array))):
            raise ValueError(f"{key}: not {' x '.join(map(str, shape))} finite numbers")
        return array
    if dataclasses.is_dataclass(hint) and isinstance(hint, type):
        return _decode(hint, raw, f"{key}.", {})
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return hint(raw)
    if origin in (tuple, list):
        if not isinstance(raw, list):
            raise TypeError(f"{key}: a list expected, got {raw!r}")
        if origin is tuple and (len(args) != 2 or args[1] is not Ellipsis):
            if len(raw) != len(args):
                raise ValueError(f"{key}: {len(args)} values expected, got {len(raw)}")
            return tuple(_value(a, v, f"{key}[]") for a, v in zip(args, raw, strict=True))
        items = [_value(args[0], v, f"{key}[]") for v in raw] if args else list(raw)
        return tuple(items) if origin is tuple else items
    if origin is dict or hint is dict:
        if not isinstance(raw, Mapping):
            raise TypeError(f"{key}: a table expected, got {raw!r}")
        inner = args[1] if args else Any
        return {k: _value(inner, v, f"{key}.{k}") for k, v in raw.items()}
    return _scalar(hint, raw, key)


def _scalar(hint: Any, raw: Any, key: str) -> Any:
    """A number, text or flag as read (an int stays an int where a float is declared, so
    that it is written back as it was; null where a float is declared is NaN)."""
    if hint is float:
        if raw is None:  # NaN, as the writer wrote it
            return math.nan
        ok = isinstance(raw, (int, float)) and not isinstance(raw, bool)
    elif hint is int:
        ok = isinstance(raw, int) and not isinstance(raw, bool)
    elif hint in (str, bool):
        ok = isinstance(raw, hint)
    else:
        ok = True
    if not ok:
        raise TypeError(f"{key}: {getattr(hint, '__name__', hint)} expected, got {raw!r}")
    return raw


# -- the reference ------------------------------------------------------------------------


def describe(cls: type, prefix: str = "") -> dict[str, str]:
    """Every key ``cls`` writes, by path (``a.b`` a key of a table, ``a[].b`` of each
    entry of a list, ``a.*`` each key of a table whose keys are data), with its meaning;
    a nested declared type's keys follow their parent's."""
    out: dict[str, str] = {}
    hints = _hints(cls)
    for f in dataclasses.fields(cls):
        d = declaration(f)
        if d.skip:
            continue
        path = f"{prefix}{d.key or f.name}"
        if d.flat:
            inner, _ = _inner(hints[f.name])
            out.update(describe(inner, prefix) if inner is not None else {})
            continue
        out[path] = d.meaning
        for part, meaning in d.parts.items():
            out[f"{path}.{part}"] = meaning
        inner, suffix = _inner(hints[f.name])
        if d.each is not None:
            out[f"{path}.*"] = d.each
            suffix = ".*"
        if inner is not None and not d.whole:
            out.update(describe(inner, f"{path}{suffix}."))
    return out


def _inner(hint: Any) -> tuple[type | None, str]:
    """The declared type inside ``hint`` and how its keys are reached (``[]``: a list's)."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        members = [a for a in args if a is not type(None)]
        return _inner(members[0]) if len(members) == 1 else (None, "")
    if origin in (tuple, list) and args and (origin is list or args[-1] is Ellipsis):
        inner, _ = _inner(args[0])
        return inner, "[]"
    if origin is dict and args:
        inner, _ = _inner(args[1])
        return inner, ""
    if dataclasses.is_dataclass(hint) and isinstance(hint, type):
        return hint, ""
    return None, ""


__all__ = ["Declared", "declaration", "declared", "decode", "describe", "doc", "encode", "keys"]
