"""Every scenario key the loader accepts, with its type, limits, default and meaning.

The keys of the top level, ``[head]``, the cameras, ``[belief]`` and ``[experiment]``
with its servo and calibration are made from their declarations
(:func:`headsim.scenario.schema.declared_keys`): kind, what is allowed and meaning as
declared, the default as declared or, for a key that a preset sets, as the presets give
it.  The scene's tables, ``[head.mapping]`` and the procedures' own tables are still read
by hand-written getters: those keys are recorded while the real loader reads every
shipped scenario and :data:`VARIANTS` of them that reach the branches no shipped file
takes (:func:`headsim.scenario.tables.collecting_keys`), their meanings written in
:data:`DESCRIPTIONS` and each procedure's ``keys``.  The documentation's scenario
reference is made from :func:`accepted_keys`, and a test fails when a key has no line or
a line no key.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from headsim.procedures.contract import procedures
from headsim.scenario.loading import (
    read_toml,
    resolve_path,
    scenario_files,
    scenario_from_document,
    set_field,
)
from headsim.scenario.scene import POSITION_KEYS, RANDOM_BOX_KEYS
from headsim.scenario.schema import DEFAULT_FROM_OTHER_KEYS, TABLE_MEANINGS, declared_keys
from headsim.scenario.tables import (
    KeyUse,
    collecting_keys,
    declared_default,
    declared_use,
    toml_value,
)
from headsim.sim import imperfections
from headsim.sim.declared import Declared, Section, Setting
from headsim.sim.heads import MAPPING, SHIPPED, shipped
from headsim.sim.model import on_head
from headsim.sim.settings import PRESETS, HeadSettings, preset


@dataclass(frozen=True)
class Key:
    """One accepted key: how the getter reads it, and what it means."""

    path: str
    kind: str
    allowed: str
    default: str
    description: str


Edit = Callable[[dict[str, Any]], dict[str, Any]]


def _without(doc: dict[str, Any], dotted: str) -> dict[str, Any]:
    """A copy of ``doc`` without the field at ``dotted``."""
    head, _, rest = dotted.partition(".")
    out = dict(doc)
    if not rest:
        out.pop(head, None)
    elif isinstance(out.get(head), dict):
        out[head] = _without(out[head], rest)
    return out


def _edits(*steps: tuple[str, Any]) -> Edit:
    """Set (or, with value None, drop) dotted fields in turn."""

    def edit(doc: dict[str, Any]) -> dict[str, Any]:
        for dotted, value in steps:
            doc = _without(doc, dotted) if value is None else set_field(doc, dotted, value)
        return doc

    return edit


#: Shipped scenarios changed to take the hand-written readers' other branches: (scenario, edit).
VARIANTS: tuple[tuple[str, Edit], ...] = (
    (  # listed markerless targets: on an object, and a world point on a surface
        "natural_field",
        _edits(
            (
                "scene.room.targets",
                [
                    {"name": "poster_centre", "object": "poster", "point_object_m": [0, 0, 0]},
                    {"name": "poster_too", "point_world_m": [-0.35, 1.6, 0.1]},
                ],
            ),
        ),
    ),
    (
        "relative_positioning",
        _edits(("scene.objects", None), ("scene.random_objects", {"count": 3})),
    ),
    (
        "tracking",
        _edits(
            ("scene.moving_target.waypoints_head_m", None),
            ("scene.moving_target.waypoints_world_m", None),
            ("scene.moving_target.random", {"waypoints": 3}),
        ),
    ),
)


def sections() -> tuple[Section, ...]:
    """The tables declared as sections: ``[head.mapping]`` and the procedures' own."""
    return (MAPPING, *(s for p in procedures() for s in p.sections))


def _declared() -> list[tuple[str, Declared]]:
    """Every declared key, as (its table's path, its declaration)."""
    return [*declared_keys(), *((s.key_path, d) for s in sections() for d in s.keys)]


def declared_uses() -> dict[str, KeyUse]:
    """Every declared key and table, by path, as its declaration says it."""
    uses = {table: KeyUse(table, "table", f"a [{table}] table", "") for table in TABLE_MEANINGS}
    for section in sections():
        kind, allowed = "table", f"a [{section.path}] table"
        if section.many:
            kind, allowed = (
                "tables",
                f"an array of tables, [[{section.path}]], at most {section.many}",
            )
        uses[section.path] = KeyUse(section.path, kind, allowed, "")
    for table, decl in _declared():
        path = f"{table}.{decl.name}" if table else decl.name
        kind, allowed = declared_use(decl)
        uses[path] = KeyUse(path, kind, allowed, _default_text(table, decl))
    return uses


def _default_text(table: str, decl: Declared) -> str:
    """``decl``'s default as the reference shows it: the presets' value where a preset
    sets the key ("depends on other keys" where they differ), else the declared one."""
    if decl in DEFAULT_FROM_OTHER_KEYS:
        return _DEPENDS
    if isinstance(decl, Setting) and decl.default is None and not (decl.optional or decl.required):
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


def collect_uses() -> dict[str, KeyUse]:
    """Every key the loader accepts, by path: the declared ones, then those the hand-written
    getters read over the shipped scenarios and :data:`VARIANTS`."""
    declared = declared_uses()
    uses: dict[str, KeyUse] = {}
    with collecting_keys() as seen:
        for path in scenario_files():
            doc = read_toml(path)
            scenario_from_document(doc, path.stem, directory=path.parent)
            _fold(uses, seen)
        for name, edit in VARIANTS:
            path = resolve_path(name)
            scenario_from_document(edit(read_toml(path)), name, directory=path.parent)
            _fold(uses, seen)
    return dict(sorted({**uses, **declared}.items()))


def _fold(uses: dict[str, KeyUse], seen: dict[str, KeyUse]) -> None:
    """Add this document's uses; a default or a range that differs between documents
    depends on other keys (the range is then shown as an example)."""
    for path, use in seen.items():
        old = uses.get(path)
        if old is None or not old.kind:
            uses[path] = use
        elif use.kind:
            default = old.default if use.default == old.default else "depends on other keys"
            allowed = old.allowed
            if use.allowed != old.allowed and not allowed.startswith("e.g. "):
                allowed = f"e.g. {allowed}"
            uses[path] = KeyUse(path, old.kind, allowed, default)
    seen.clear()


def descriptions() -> dict[str, str]:
    """Every key's meaning: the shared ones, then each procedure's own."""
    return {
        **TABLE_MEANINGS,
        **{s.path: s.meaning for s in sections()},
        **{f"{t}.{d.name}" if t else d.name: d.meaning for t, d in _declared()},
        **DESCRIPTIONS,
        **{k: v for p in procedures() for k, v in p.keys.items()},
    }


def accepted_keys() -> list[Key]:
    """Every accepted key with its meaning (KeyError-free: a key without a line gets "").

    A key a procedure declares that no shipped scenario or variant reaches (one registered
    from outside the package) is listed with its meaning alone, after the others."""
    meanings = descriptions()
    uses = collect_uses()
    return [
        *(
            Key(u.path, u.kind, u.allowed, u.default, meanings.get(u.path, ""))
            for u in uses.values()
        ),
        *(
            Key(path, "", "", "", text)
            for p in procedures()
            for path, text in p.keys.items()
            if path not in uses
        ),
    ]


#: One line per key that a hand-written getter reads: what it means, with its unit (a
#: declared key's meaning is in its declaration, a procedure's own keys' in its
#: ``Procedure.keys``).
DESCRIPTIONS: dict[str, str] = {
    "fast": "Fields merged over the file by `--fast`: tables key by key, other values replaced.",
    "experiment.calibration.positions_world_m": "The ball positions [[x, y, z], ...] in W, m, given instead of drawn (`targets` is their number).",
    "scene": "What the procedure measures and where it is.",
    "scene.targets": "Fixed targets (model2, model1; for calibration: optional check targets).",
    "scene.targets[].name": "The target's name, unique (default `target_N`).",
    "scene.targets[].body": "The marker body that stands for the target.",
    **{f"scene.targets[].{k}": v for k, v in POSITION_KEYS.items()},
    "scene.random_targets": "More targets drawn from the seed, named `random_N`.",
    "scene.random_targets.count": "Number of random targets.",
    "scene.random_targets.body": "The marker body of every random target.",
    **{f"scene.random_targets.{k}": v for k, v in RANDOM_BOX_KEYS.items()},
    "scene.random_targets.within": "`box` refuses a drawn point out of reach and draws again one the scene hides; `reach` draws any refused point again (each redraw counted).",
    "scene.room": "A textured room around the head (every procedure): floor, walls and table with generated textures, objects, clutter from the seed, and the light.",
    "scene.room.surface": "Texture class of the floor, walls and table: `pink` (1/f noise), `grating`, `low` (faint gradient), `repetitive` (stripes).",
    "scene.room.table_top_z_m": "Height of the table top in W's z, m (the eyes are about 0.2 m up; default -0.35); the clutter rests on it.",
    "scene.room.clutter": "Objects drawn from the seed (box, cylinder or sphere, 3-8 cm half-size, a texture class each), resting on the table.",
    "scene.room.clutter_depth_m": "Range of W's y (depth in front of the head) of the clutter's centres, m.",
    "scene.room.targets": "Markerless targets (`model2`, `model1`; told by a click in camera 1's image): a count drawn from the seed where the start pose shows both cameras (0: none), or a list.",
    "scene.room.targets[].name": "The listed target's name, unique (`surface_` is reserved for drawn ones). Listed targets are measured in file order.",
    "scene.room.targets[].object": "The room object the point lies on (an objects entry, `clutter_N`, `room_floor`, `room_table`, `room_wall_*`).",
    "scene.room.targets[].point_object_m": "The point in the object's frame, m; must lie within 1 mm of its surface.",
    "scene.room.targets[].point_world_m": "Without `object`: the point in W, m; must lie within 1 mm of a surface of the room.",
    "scene.room.targets_depth_m": "Depth range in H of the markerless targets, m (a draw outside is drawn again, counted).",
    "scene.room.targets_lateral": "Largest |x_h / z_h| of a markerless target's draw direction (0.25: the shared field).",
    "scene.room.targets_vertical": "Largest |y_h / z_h| of a markerless target's draw direction.",
    "scene.room.click_error_px": "Standard deviation of the click that tells the head a markerless target, px per axis.",
    "scene.room.targets_as": "`surface`: each target by correlation; `markers`: an emissive marker put 5 mm out along the surface's normal, found by its colour (the marker twin).",
    "scene.room.band_px": "Half-height of the band along camera 1's row in which camera 2 searches the clicked point, px (the head knows no focal length).",
    "scene.room.light": "The key light and the ambient level.",
    "scene.room.light.direction_world": "Direction the key light shines along, in W (normalised).",
    "scene.room.light.diffuse": "Key light's diffuse intensity, 0-1.",
    "scene.room.light.ambient": "Ambient light everywhere, 0-1.",
    "scene.room.light.shadows": "Whether the key light casts shadows (a shadow map: dearer renders).",
    "scene.room.objects": "Textured objects placed in the room.",
    "scene.room.objects[].name": "The object's name, unique (default `item_N`; `clutter_`, `room_` and the scenes' bodies are reserved).",
    "scene.room.objects[].shape": "`box`, `cylinder`, `sphere`, `plane` or `mesh` (its `vertices_m` and `faces`, no `size_m`).",
    "scene.room.objects[].size_m": "MuJoCo's sizes, m: a box's half-lengths, a cylinder's radius and half-height (then 0), a sphere's radius (then 0, 0), a plane's half-sides (then 0).",
    "scene.room.objects[].pos_world_m": "The object's centre in W, m.",
    "scene.room.objects[].yaw_rad": "Rotation about W's z, rad.",
    "scene.room.objects[].pitch_rad": "Then about the object's own x, rad (a plane at pi/2 stands up facing the head).",
    "scene.room.objects[].texture": "Texture class: `pink`, `grating`, `low` or `repetitive`.",
    "scene.room.objects[].texture_seed": "Seed of the object's texture; default from the scenario's seed.",
    "scene.room.objects[].period_px": "`grating` and `repetitive`: the period in texture pixels (256 to a tile).",
    "scene.room.objects[].orientation_rad": "`grating` and `repetitive`: direction the pattern varies along, rad from the texture's columns.",
    "scene.room.objects[].checks": "`repetitive`: checks instead of stripes.",
    "scene.room.objects[].vertices_m": "`mesh`: its vertices [[x, y, z], ...] in the object's frame (4-1000, within 2 m of its origin), m.",
    "scene.room.objects[].faces": "`mesh`: its triangles [[i, j, k], ...] of vertex indices, counter-clockwise seen from outside (each textured by projecting it onto the object-frame plane it faces most).",
    "scene.room.objects[].tile_m": "`plane` and `mesh`: the side of one texture tile on the surface, m.",
}
