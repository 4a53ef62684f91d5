"""Every scenario key the loader accepts, with its type, limits, default and meaning, made
from the declarations alone.

The keys of the top level, ``[head]``, the cameras, ``[belief]`` and ``[experiment]`` with
its servo and calibration are :func:`headsim.scenario.schema.declared_keys`; every other
table is a :class:`~headsim.sim.declared.Section` beside its reader: ``[head.mapping]``
(:data:`headsim.sim.heads.MAPPING`), the scene's shared tables and the room
(:mod:`headsim.scenario.scene`, :mod:`headsim.scenario.room`) and each procedure's own
(its ``Procedure.keys``).  Kind, what is allowed and meaning are as declared; the default
as declared or, for a key that a preset sets, as the presets give it.  The
documentation's scenario reference is made from :func:`accepted_keys`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from headsim.procedures.contract import procedures
from headsim.scenario import room, scene
from headsim.scenario.schema import DEFAULT_FROM_OTHER_KEYS, TABLE_MEANINGS, declared_keys
from headsim.scenario.tables import declared_default, declared_use, toml_value
from headsim.sim import imperfections
from headsim.sim.declared import Declared, Section, Setting, Text
from headsim.sim.heads import MAPPING, SHIPPED, shipped
from headsim.sim.model import on_head
from headsim.sim.settings import PRESETS, HeadSettings, preset


@dataclass(frozen=True)
class Key:
    """One accepted key: its dotted path (``[]`` for any entry of an array of tables),
    kind, what is allowed, default as TOML writes it ("": required) and meaning."""

    path: str
    kind: str
    allowed: str
    default: str
    description: str


def sections() -> tuple[Section, ...]:
    """The tables declared as sections: ``[head.mapping]``, the scene's and the procedures'."""
    own = (s for p in procedures() for s in p.keys)
    return (MAPPING, *scene.SECTIONS, *room.SECTIONS, *own)


def _declared() -> list[tuple[str, Declared]]:
    """Every declared key, as (its table's path, its declaration)."""
    return [*declared_keys(), *((s.key_path, d) for s in sections() for d in s.keys)]


def accepted_keys() -> list[Key]:
    """Every accepted key with its meaning, by path."""
    keys = {t: Key(t, "table", f"a [{t}] table", "", m) for t, m in TABLE_MEANINGS.items()}
    for s in sections():
        kind, allowed = "table", f"a [{s.path}] table"
        if s.many:
            kind, allowed = "tables", f"an array of tables, [[{s.path}]], at most {s.many}"
        keys[s.path] = Key(s.path, kind, allowed, "", s.meaning)
    for table, decl in _declared():
        path = f"{table}.{decl.name}" if table else decl.name
        kind, allowed = declared_use(decl)
        if path in keys and keys[path].kind == "tables":  # a count, or the entries listed
            kind, allowed = f"{kind} or tables", f"{allowed}; or {keys[path].allowed}"
        keys[path] = Key(path, kind, allowed, _default_text(table, decl), decl.meaning)
    return sorted(keys.values(), key=lambda k: k.path)


def descriptions() -> dict[str, str]:
    """Every key's meaning, by path."""
    return {k.path: k.description for k in accepted_keys()}


def _default_text(table: str, decl: Declared) -> str:
    """``decl``'s default as the reference shows it: the presets' value where a preset
    sets the key ("depends on other keys" where they differ), else the declared one."""
    if decl in DEFAULT_FROM_OTHER_KEYS:
        return _DEPENDS
    if isinstance(decl, Setting) and decl.default is None and not (decl.optional or decl.required):
        return _DEPENDS
    if isinstance(decl, Text) and decl.derived:
        return _DEPENDS
    values = {toml_value(v) for v in _preset_values(table, decl)}
    if len(values) > 1:
        return _DEPENDS
    if values:
        return values.pop()
    return toml_value(declared_default(decl))


_DEPENDS = "depends on other keys"


def _preset_values(table: str, decl: Declared) -> list[Any]:
    """What each preset on each shipped head gives ``decl``'s key of ``table`` (empty: a
    preset does not set it)."""
    heads = [on_head(preset(p), shipped(h)) for p in PRESETS for h in SHIPPED]

    def holder(head: HeadSettings) -> Any:
        if table == "head":
            return head.render if decl.name.startswith("render_") else head
        if table == "belief":
            return head.believed
        return head.cameras[int(table[-1]) - 1] if table in ("cam1", "cam2") else None

    name = decl.name.removeprefix("render_") if table == "head" else decl.name
    if table in ("cam1", "cam2") and name in imperfections.meanings():
        return [holder(h).value(name) for h in heads]
    return [getattr(holder(h), name) for h in heads if hasattr(holder(h), name)]
