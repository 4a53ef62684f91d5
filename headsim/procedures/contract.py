"""The procedure contract and its registry: each scenario's ``[experiment] procedure`` names one.

A :class:`Procedure` is what the generic code (the scenario reader, the runner,
results.json, the summary, the recording, the two reference pages) needs of a
procedure: its result's declared type (whose declaration gives results.json's
``experiment`` keys and what they mean) and the functions the result is handed
back to.  It also declares what its own scenario keys mean (``keys``); the
reference pages are made from both.

This module is the interface the generic layers call and the procedures
implement, so it sits below them (``tools/import_graph.py``'s LAYERS: below
``scenario``): it names none of their types (the arguments it passes on are
``Any`` here; each procedure's own functions are typed) and loads no procedure.
Each module of :mod:`headsim.procedures` registers its procedure when imported;
the package root hands :func:`on_first_lookup` the function that imports them
all, which :func:`get` and :func:`names` call once, on first use.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from headsim.sim.declared import Section

if TYPE_CHECKING:
    from headsim.active.measurement import HeadKnowledge
    from headsim.sim.settings import HeadSettings

#: ``read_scene(scene_table, ctx, settings, seed) -> SceneSpec``: the procedure's part of
#: ``[scene]`` (``headsim.scenario.scene.SceneReader``, typed there).
SceneReader = Callable[[Any, Any, "HeadSettings", int], Any]

#: What :func:`discover` calls: each imports a package of procedures.
_LOADERS: list[Callable[[], object]] = []
_loaded = False
#: Held while loading: a lookup from another thread (a batch of heads, a sweep's workers)
#: waits for the whole registry instead of seeing it half filled.
_LOADING = threading.RLock()


class _InLoad(threading.local):
    active = False


#: Whether this thread is loading (a module's import that looks a procedure up waits on
#: no one and sees what is registered so far).
_IN_LOAD = _InLoad()


def on_first_lookup(load: Callable[[], object]) -> None:
    """Have the first lookup call ``load`` (it imports procedure modules, which register)."""
    global _loaded
    _LOADERS.append(load)
    _loaded = False


def discover() -> None:
    """Import every package of procedures handed to :func:`on_first_lookup`, once."""
    global _loaded
    if _loaded:
        return
    with _LOADING:
        if _loaded or _IN_LOAD.active:  # loaded while this thread waited, or loading now
            return
        _IN_LOAD.active = True
        try:
            for load in tuple(_LOADERS):
                load()
            _loaded = True
        finally:
            _IN_LOAD.active = False


def _no_lines(result: Any, paper: bool) -> list[str]:
    return []


def _no_failures(result: Any) -> tuple[str, ...]:
    return ()


def _no_rows(result: Any, log: Any) -> None:
    return None


def _no_options(table: Any, calibration: Any) -> dict[str, Any]:
    return {}


def _each_target(scenario: Any) -> int:
    return len(scenario.scene.targets)


def _measured_line(result: Any, measured: int) -> str:
    return f"OK: {measured} measurement{'' if measured == 1 else 's'}, none failed"


@dataclass(frozen=True)
class Procedure:
    """One procedure, as the runner and the writers see it.

    ``run(scenario, hub, knowledge, label)``: the records of its measurements and
    its result (``knowledge`` is what the head knows, ``label`` says whether it was
    calibrated), of the declared type ``result`` (:func:`headsim.codec.declared`; or
    one of the tuple's): its fields are results.json's ``experiment`` keys beside
    ``procedure`` (:func:`headsim.codec.encode` writes them), and their declarations
    say what they mean (:attr:`results`).  The other functions take that result:
    ``summary(result, paper)`` its lines in the summary table; ``ok_line(result,
    measured)`` the table's last line when the run succeeded; ``failures`` what failed
    beyond its measurements; ``rows(result, log)`` what it adds to a recording, through
    ``log.rec``.  ``scene`` is the MJCF scene (``headsim.sim.names.SCENES``) it runs in.

    Its scenario block: ``options(table, calibration)`` reads the ``[experiment]``
    keys it takes (the :class:`~headsim.scenario.spec.ExperimentSpec` fields they
    set) and checks them against the calibration before it; ``read_scene`` reads its
    ``[scene]`` tables (None: it takes none); ``fixations(scenario)`` is how many
    fixations it makes after the calibration (for the progress bar).

    What its keys mean: ``keys`` the scenario tables only it reads (``[experiment.NAME]``,
    ``[scene.NAME]``), each key declared with its type, range, default and meaning, which
    its reader reads through; both reference pages are made from them and from its
    result's declaration.
    ``rank`` orders the procedures in a scenario's error and the references (lower
    first, then by name).  ``reach`` is the reach check its targets take (``"model2"``:
    each eye fixates from the start pose; ``"model1"``: the neck turns too);
    ``markerless`` whether it measures ``[scene.room] targets``.
    """

    name: str
    scene: str
    run: Callable[[Any, Any, HeadKnowledge, str], tuple[Sequence[Any], Any]]
    result: type | tuple[type, ...]
    summary: Callable[[Any, bool], list[str]] = _no_lines
    ok_line: Callable[[Any, int], str] = _measured_line
    failures: Callable[[Any], tuple[str, ...]] = _no_failures
    rows: Callable[[Any, Any], None] = _no_rows
    options: Callable[[Any, Any], dict[str, Any]] = _no_options
    read_scene: SceneReader | None = None
    fixations: Callable[[Any], int] = _each_target
    needs: frozenset[str] = frozenset()
    keys: Sequence[Section] = ()
    rank: int = 100
    reach: str = "model2"
    markerless: bool = False

    @property
    def results(self) -> dict[str, str]:
        """What its results.json ``experiment`` keys beside ``procedure`` mean, from its
        result type's declaration (paths relative to ``experiment``: ``a.b``, ``a[].b``,
        ``a.*``, as in :mod:`headsim.runs.results_reference`)."""
        from headsim.codec import describe  # numpy: not at `import headsim`

        out: dict[str, str] = {}
        for kind in self.result if isinstance(self.result, tuple) else (self.result,):
            for path, meaning in describe(kind).items():
                out.setdefault(path, meaning)
        return out


#: Every registered procedure, by name.
REGISTRY: dict[str, Procedure] = {}


def register(procedure: Procedure) -> Procedure:
    """Add ``procedure`` under its name (a second one by the same name is an error)."""
    known = REGISTRY.get(procedure.name)
    if known is not None and known is not procedure:
        raise ValueError(f"a procedure named {procedure.name!r} is already registered")
    REGISTRY[procedure.name] = procedure
    return procedure


def procedures() -> tuple[Procedure, ...]:
    """Every procedure, by rank, then by name."""
    discover()
    return tuple(sorted(REGISTRY.values(), key=lambda p: (p.rank, p.name)))


def names() -> tuple[str, ...]:
    """The names of every procedure, by rank, then by name."""
    return tuple(p.name for p in procedures())


def get(name: str) -> Procedure:
    """The procedure named ``name``."""
    if name not in REGISTRY:
        discover()
    try:
        return REGISTRY[name]
    except KeyError:
        raise KeyError(f"no procedure named {name!r}; known: {', '.join(names())}") from None


__all__ = [
    "REGISTRY",
    "Procedure",
    "discover",
    "get",
    "names",
    "procedures",
    "register",
]
