"""Loading a scenario file: read, merge ``[fast]``, draw the random parts, check everything.

:func:`load_scenario` reads a file, draws the random parts with the seed,
checks every field and every target's reach, and returns a frozen
:class:`headsim.scenario.spec.Scenario`; anything wrong raises
:class:`headsim.scenario.tables.ScenarioError` before anything is rendered or
written.  A ``[fast]`` table holds overrides merged over the file by
``--fast`` (tables merge key by key, everything else is replaced); both
variants are checked.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from importlib import resources
from pathlib import Path
from typing import Any

from headsim.procedures import contract as registry
from headsim.scenario.reach import ReachHead
from headsim.scenario.reach_check import check_reach
from headsim.scenario.scene import read_scene
from headsim.scenario.schema import DESCRIPTION, FIRST_TABLES, SEED, read_experiment, read_head
from headsim.scenario.spec import Scenario
from headsim.scenario.tables import Context, ScenarioError, Table, describe_value
from headsim.scenario.toml_file import deep_line, read_toml, text_or_empty
from headsim.sim.settings import HeadSettings

#: Where ``headsim list`` and ``headsim run NAME`` look for scenario files: the
#: repository's scenarios/, installed as package data.
SCENARIOS_DIR = Path(str(resources.files("headsim.scenarios")))


def _merge(base: dict[str, Any], override: dict[str, Any]) -> dict[str, Any]:
    """``base`` with ``override`` merged in: tables key by key, other values replaced."""
    merged = dict(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = _merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _drop_field(doc: dict[str, Any], dotted: str) -> dict[str, Any]:
    head, _, rest = dotted.partition(".")
    if head not in doc:
        return doc
    out = dict(doc)
    if not rest:
        del out[head]
    elif isinstance(out[head], dict):
        out[head] = _drop_field(out[head], rest)
    return out


def set_field(doc: dict[str, Any], dotted: str, value: Any) -> dict[str, Any]:
    """A copy of ``doc`` with the field at ``dotted`` (e.g. ``"cam1.kx"``) set to ``value``."""
    head, _, rest = dotted.partition(".")
    out = dict(doc)
    if not rest:
        out[head] = value
        return out
    child = out.get(head, {})
    if not isinstance(child, dict):
        raise ValueError(f"{dotted}: {head} is not a table")
    out[head] = set_field(child, rest, value)
    return out


def resolve_path(name_or_path: str | Path) -> Path:
    """A scenario file: a path, or the name of a file in ``scenarios/`` (without .toml)."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    candidate = SCENARIOS_DIR / f"{name_or_path}.toml"
    if isinstance(name_or_path, str) and "/" not in name_or_path and candidate.is_file():
        return candidate
    available = ", ".join(p.stem for p in scenario_files()) or "none"
    raise ScenarioError(
        str(name_or_path), "", "no such scenario file", f"a .toml path or one of: {available}"
    )


def load_scenario(
    name_or_path: str | Path,
    *,
    fast: bool = False,
    seed: int | None = None,
    overrides: dict[str, Any] | None = None,
) -> Scenario:
    """Read, merge ``[fast]`` if asked, draw the random parts, check everything.

    Both the full and the fast variant are checked, whichever is returned.
    ``seed`` overrides the file's ``seed``; ``overrides`` sets fields by
    dotted name (``{"cam1.kx": 700.0}``) in both variants, checked like the
    file's own.  Raises :class:`ScenarioError`.
    """
    path = resolve_path(name_or_path)
    source = str(path)
    doc = read_toml(path)
    try:
        return _load(doc, path, fast=fast, seed=seed, overrides=overrides)
    except RecursionError as err:  # a structure nested too deeply for the checks
        raise ScenarioError(
            source, "", f"nested too deeply{deep_line(text_or_empty(path))}"
        ) from err


def scenario_from_document(
    doc: dict[str, Any],
    name: str,
    *,
    fast: bool = False,
    seed: int | None = None,
    overrides: dict[str, Any] | None = None,
    directory: Path | None = None,
) -> Scenario:
    """A scenario given as a parsed document (the tables of a scenario file), named ``name``.

    Checked like a file by :func:`load_scenario`; how a study or a benchmark
    describes its experiment without writing a file.  ``directory`` stands for
    the file's folder: relative paths in ``doc`` are relative to it (default:
    the working directory).
    """
    path = (Path.cwd() if directory is None else Path(directory)) / f"{name}.toml"
    return _load(doc, path, fast=fast, seed=seed, overrides=overrides)


def _check_head_fits(settings: HeadSettings, procedure: str, ctx: Context) -> None:
    """The procedure's needs of the head (``Procedure.needs``), named where they fail."""
    needs = registry.get(procedure).needs
    mapping, head = settings.head.mapping, settings.head.name
    if "independent_eyes" in needs and not mapping.independent:
        raise ctx.error(
            "experiment.procedure",
            f"{procedure} needs a motor per eye, and head {head!r} couples its eyes",
            'head.model = "independent_eyes", or an MJCF head whose head.mapping.eyes = "independent"',
        )
    if "neck_yaw" in needs and mapping.neck_yaw is None:
        raise ctx.error(
            "head.mapping.neck_yaw",
            f"not given, and {procedure} turns the neck to the midline",
            "the neck's yaw joint, or a procedure that keeps the neck still (model2)",
        )


def _load(
    doc: dict[str, Any],
    path: Path,
    *,
    fast: bool,
    seed: int | None,
    overrides: dict[str, Any] | None,
) -> Scenario:
    source = str(path)
    if seed is not None:  # checked as the file's own seed is
        Table({SEED.name: seed}, "", Context(source, None)).setting(SEED)
    for dotted, value in (overrides or {}).items():
        try:
            doc = set_field(doc, dotted, value)
        except ValueError as err:
            raise ScenarioError(source, dotted, f"cannot be set: {err}") from err
    fast_doc = doc.get("fast", {})
    if overrides and isinstance(fast_doc, dict):
        # An override wins over the fast table's value for the same field.
        for dotted in overrides:
            fast_doc = _drop_field(fast_doc, dotted)
    if not isinstance(fast_doc, dict):
        raise ScenarioError(
            source,
            "fast",
            f"must be a table, got {describe_value(fast_doc)}",
            "a [fast] table of overrides",
        )
    for key in fast_doc:
        if key not in FIRST_TABLES or key == "description":
            allowed = ", ".join(k for k in FIRST_TABLES if k != "description")
            raise ScenarioError(source, f"fast.{key}", "unknown key", allowed)
    files: dict[Path, dict[str, Any]] = {}  # each calibration file read once for both variants
    full = _build(doc, Context(source, None), path, False, seed, files)
    quick = _build(_merge(doc, fast_doc), Context(source, fast_doc), path, True, seed, files)
    return quick if fast else full


def _build(
    doc: dict[str, Any],
    ctx: Context,
    path: Path,
    fast: bool,
    seed: int | None,
    files: dict[Path, dict[str, Any]],
) -> Scenario:
    top = Table(doc, "", ctx)
    description = top.setting(DESCRIPTION)
    file_seed = top.setting(SEED)
    seed = file_seed if seed is None else seed
    settings, preset_name, settle, sources = read_head(top, ctx, path.parent)
    settings = replace(settings, seed=seed)
    experiment = read_experiment(top, ctx, preset_name)
    _check_head_fits(settings, experiment.procedure, ctx)
    calibration = experiment.calibration
    stored = None
    if calibration is not None and calibration.source is not None:
        from headsim.active.calibration_file import (
            CalibrationFileError,
            calibration_for_head,
            read_calibration_document,
        )

        source = Path(calibration.source)
        if not source.is_absolute():  # relative to the scenario file, like the file's own paths
            source = path.parent / source
            experiment = replace(experiment, calibration=replace(calibration, source=str(source)))
        try:
            if source not in files:
                files[source] = read_calibration_document(source)
            stored = calibration_for_head(files[source], source, settings)
        except CalibrationFileError as err:
            raise ctx.error("experiment.calibration.from", str(err)) from err
    if experiment.goal_columns_px is not None and calibration and calibration.source:
        raise ctx.error(
            "experiment.goal_columns_px",
            "given with experiment.calibration.from",
            "one of the two (a calibration file carries its own goal columns)",
        )
    for index, u in enumerate(experiment.goal_columns_px or ()):
        width = settings.cameras[index].width
        if not u <= width - 1:
            raise ctx.error(
                f"experiment.goal_columns_px[{index}]",
                f"{u:g} px is outside camera {index + 1}'s image",
                f"a column in [0, {width - 1}] px",
            )
    scene = read_scene(top, ctx, experiment.procedure, settings, seed)
    top.has("fast")
    top.done()
    scenario = Scenario(
        name=path.stem,
        path=path,
        description=description,
        seed=seed,
        fast=fast,
        preset=preset_name,
        settings=settings,
        settle_mode=settle,
        scene=scene,
        experiment=experiment,
        stored_calibration=stored,
        belief_sources=sources,
    )
    _check_servo(ctx, scenario)
    check_reach(ctx, scenario)
    return scenario


def _check_servo(ctx: Context, scenario: Scenario) -> None:
    """The servo's probe must fit in the eye's range (a probe step moves both eyes)."""
    lo, hi = ReachHead.of(scenario.settings).eye_range
    resolution = scenario.settings.encoder_resolution_rad
    half_range = (hi - lo) / 2.0
    steps = scenario.experiment.servo.probe_steps
    if steps * resolution > half_range:
        raise ctx.error(
            "experiment.servo.probe_steps",
            f"{steps} encoder steps of {resolution:.3g} rad turn the eyes by "
            f"{steps * resolution:.3g} rad, more than they can turn from the centre of their "
            f"range [{lo:g}, {hi:g}] rad",
            f"at most {int(half_range / resolution)} steps",
        )


def scenario_files(directory: Path | None = None) -> list[Path]:
    """The scenario files in ``directory`` (default ``scenarios/``), sorted by name."""
    directory = SCENARIOS_DIR if directory is None else directory
    return sorted(directory.glob("*.toml")) if directory.is_dir() else []


def describe_scenarios(directory: Path | None = None) -> Iterator[tuple[str, str, str]]:
    """(name, head, description) of each scenario file; an unreadable file has head ""
    and a description that says why."""
    for path in scenario_files(directory):
        try:
            scenario = load_scenario(path)
            yield path.stem, scenario.settings.head.name, scenario.description
        except ScenarioError as err:
            yield path.stem, "", f"INVALID: {err}"
        except Exception as err:  # one unreadable file must not end the listing
            yield path.stem, "", f"INVALID: cannot be checked: {type(err).__name__}: {err}"
