"""headsim from Python: load a scenario, run it, read its measurements.

What ``headsim.load_scenario``, ``headsim.run`` and ``docs/python.md`` stand on::

    import headsim
    result = headsim.run("quickstart", seed=1, fast=True)
    for row in result.measurements:          # MeasurementRow, frozen
        print(row.name, row.error_pct_of_depth)
    columns = result.table()                 # pandas.DataFrame(columns)

:func:`run` goes through the same runner as ``headsim run``
(:func:`headsim.runs.runner.run_scenario`) and writes nothing unless asked:
``out`` for results.json and summary.txt (the bytes ``headsim run`` writes),
``record`` for a Rerun recording.  Bad input raises
:class:`headsim.scenario.tables.ScenarioError`, one line naming the field and
what is allowed, before anything renders.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from headsim.runs.result import RunResult
from headsim.scenario.loading import load_scenario as _load_scenario
from headsim.scenario.spec import Scenario
from headsim.scenario.tables import ScenarioError


def dotted_overrides(overrides: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested tables flattened to dotted keys: ``{"cam1": {"kx": 700.0}}`` -> ``{"cam1.kx": 700.0}``.

    A key may be dotted already (``{"cam1.kx": 700.0}``); a table merges into the
    file's table key by key, any other value (an array of tables too) replaces it.
    """
    flat: dict[str, Any] = {}
    for key, value in overrides.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, Mapping):  # an empty table changes nothing
            flat.update(dotted_overrides(value, dotted + "."))
        else:
            flat[dotted] = value
    return flat


def load_scenario(
    name_or_path: str | Path,
    *,
    fast: bool = False,
    seed: int | None = None,
    overrides: Mapping[str, Any] | None = None,
    **tables: Any,
) -> Scenario:
    """A checked scenario: a file in ``scenarios/`` by name (``"quickstart"``) or a path.

    ``fast``: the file's ``[fast]`` variant.  ``seed``: in place of the file's.
    Fields to change go as keywords named after the file's top-level tables, or
    as ``overrides`` with dotted keys, or both::

        load_scenario("quickstart", cam1={"kx": 700.0})
        load_scenario("quickstart", overrides={"cam1.kx": 700.0, "scene.count": 4})

    They apply to the full and the fast variant alike and are checked like the
    file's own.  Raises :class:`ScenarioError` (an unknown key or a value out of
    range names the field and what is allowed).
    """
    changes = dotted_overrides({**tables, **(overrides or {})})
    for key in changes:
        if not key or any(not part for part in key.split(".")):
            raise ScenarioError(
                str(name_or_path), key, "not a field name", 'dotted names such as "cam1.kx"'
            )
    return _load_scenario(name_or_path, fast=fast, seed=seed, overrides=changes)


def run(
    scenario: Scenario | str | Path,
    *,
    seed: int | None = None,
    fast: bool = False,
    out: str | Path | None = None,
    record: str | Path | None = None,
    progress: bool = False,
) -> RunResult:
    """Run a scenario (a :class:`Scenario`, or a name or path for :func:`load_scenario`).

    ``seed``, ``fast``: how to load a name or path; a :class:`Scenario` was
    drawn with its own seed and variant already (giving another is a
    :class:`ScenarioError`).  ``out``: a folder to write results.json and
    summary.txt into, byte for byte what ``headsim run --out`` writes;
    ``record``: a Rerun recording (.rrd) to write; ``progress``: the progress
    lines on stderr.  Nothing is written unless asked.  The same scenario and
    seed give the same measurements.
    """
    from headsim.files import write_json_atomic, write_text_atomic
    from headsim.runs.events import Subscriber
    from headsim.runs.outputs import Outputs
    from headsim.runs.runner import run_scenario
    from headsim.runs.serialise import results_payload
    from headsim.runs.summary import summary_text

    if isinstance(scenario, Scenario):
        for name, given, drawn in (("seed", seed, scenario.seed), ("fast", fast, scenario.fast)):
            if given not in (None, False) and given != drawn:
                raise ScenarioError(
                    str(scenario.path),
                    name,
                    f"the scenario was loaded with {name} = {drawn!r}",
                    f"pass {name} to headsim.load_scenario",
                )
    else:
        scenario = _load_scenario(scenario, fast=fast, seed=seed)
    outputs = Outputs()
    try:
        folder = None if out is None else outputs.directory(out, "out")
        rrd = None if record is None else outputs.file(record, "record", atomic=False)
        subscribers: list[Subscriber] = []
        if progress:
            from headsim.runs.progress import Counter, RunProgress

            subscribers.append(RunProgress(Counter(scenario.fixations, unit="fixations")))
        recorder = None
        if rrd is not None:
            from headsim.runs.recording import Recorder

            recorder = Recorder(rrd, scenario)
            subscribers.append(recorder)
        try:
            result = run_scenario(scenario, subscribers)
        finally:
            if recorder is not None:
                recorder.close()
        if folder is not None:
            write_json_atomic(folder / "results.json", results_payload(result))
            write_text_atomic(folder / "summary.txt", summary_text(result) + "\n")
    finally:
        outputs.remove_empty_created()
    return result


__all__ = ["dotted_overrides", "load_scenario", "run"]
