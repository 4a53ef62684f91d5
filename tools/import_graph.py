"""Import graph of headsim: circles, upward imports between layers, the largest modules.

    python tools/import_graph.py [REPO_ROOT]

The layers, low to high, are LAYERS (a module's layer is the longest entry that
its dotted path under headsim/ starts with: its package, or a module named there). An import from a module to a
higher layer is upward. Every import counts: inside functions, in a
TYPE_CHECKING block (a type a module names is a dependency), and a load by
``importlib.import_module`` of a literal ``"headsim..."`` name or of a
module-level constant holding one (``PACKAGE + "." + name``: every module of
PACKAGE, the way a discovery loads them). Exit status 1 when there is a circle, an upward import or a module
over MAX_LINES lines.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

LAYERS = (
    "version",
    "errors",
    "files",
    "codec",
    "paper",
    "geometry",
    "estimators",
    "sim",
    "vision",
    # The Head interface, its recordings and replays: the simulator is one head.
    "head",
    "stereo",
    "active",
    "live",
    "lockstep",
    # The procedure contract: the interface the scenario reader and the runner call and the
    # procedures implement, so below both (it names none of their types).
    "procedures.contract",
    "scenario",
    "runs",
    "procedures",
    # Lockstep's scenario jobs: a sweep's chunk of scenarios run as heads over arrays (they
    # read scenarios, calibrate and return the runner's results, so above procedures).
    "lockstep.model2_run",
    "lockstep.runs",
    "studies",
    "envs",
    "cli",
)
#: Modules are sized by concern; none is over about this many lines.
MAX_LINES = 800


def module_name(root: Path, path: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _constants(tree: ast.AST) -> dict[str, str]:
    """Module-level names bound to a string literal (``BUILT_IN = "headsim.x"``)."""
    found: dict[str, str] = {}
    for node in getattr(tree, "body", []):
        value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
        if isinstance(value, ast.Constant) and isinstance(value.value, str):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            found.update((t.id, value.value) for t in targets if isinstance(t, ast.Name))
    return found


def _loaded(call: ast.Call, constants: dict[str, str]) -> str | None:
    """The module an ``importlib.import_module(...)`` call loads, where the source names it."""
    func = call.func
    name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
    if name != "import_module" or not call.args:
        return None
    arg = call.args[0]
    if isinstance(arg, ast.BinOp) and isinstance(arg.op, ast.Add):
        # PACKAGE + "." + name: a discovery that may load every module of PACKAGE.
        while isinstance(arg, ast.BinOp):
            arg = arg.left
        prefix = _loaded(ast.Call(func=call.func, args=[arg], keywords=[]), constants)
        return None if prefix is None else f"{prefix}.*"
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return arg.value
    return constants.get(arg.id) if isinstance(arg, ast.Name) else None


def imports(tree: ast.AST) -> list[str]:
    """Every headsim module or name imported, TYPE_CHECKING blocks and importlib loads included."""
    found: list[str] = []
    constants = _constants(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.extend(f"{node.module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Import):
            found.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.Call) and (loaded := _loaded(node, constants)):
            found.append(loaded)
    return [name for name in found if name.startswith("headsim")]


def graph(root: Path) -> tuple[dict[str, set[str]], dict[str, int]]:
    paths = {module_name(root, p): p for p in (root / "headsim").rglob("*.py")}
    edges: dict[str, set[str]] = {}
    for name, path in paths.items():
        targets: set[str] = set()
        for imported in imports(ast.parse(path.read_text())):
            if imported.endswith(".*"):
                package = imported[:-1]
                targets.update(m for m in paths if m.startswith(package) and m != name)
                continue
            while imported not in paths and "." in imported:
                imported = imported.rsplit(".", 1)[0]
            if imported in paths and imported != name:
                targets.add(imported)
        edges[name] = targets
    lines = {name: len(path.read_text().splitlines()) for name, path in paths.items()}
    return edges, lines


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def strong(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    sys.setrecursionlimit(10_000)
    for v in edges:
        if v not in index:
            strong(v)
    return found


def layer(name: str) -> int:
    """The index of the longest entry of LAYERS that ``name`` (after ``headsim.``) starts with."""
    parts = name.split(".")[1:]
    for end in range(len(parts), 0, -1):
        if ".".join(parts[:end]) in LAYERS:
            return LAYERS.index(".".join(parts[:end]))
    return -1


def main() -> int:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1]
    edges, lines = graph(root)
    found = circles(edges)
    upward = sorted(
        (m, t) for m, ts in edges.items() for t in ts if 0 <= layer(m) < layer(t) and layer(t) >= 0
    )
    unlayered = sorted(m for m in edges if m != "headsim" and layer(m) < 0)
    largest = sorted(lines.items(), key=lambda item: -item[1])
    print(f"modules: {len(edges)}; imports between them: {sum(map(len, edges.values()))}")
    print(f"circles: {len(found)}", *(" <-> ".join(c) for c in found), sep="\n  ")
    print(f"upward imports ({' < '.join(LAYERS)}): {len(upward)}")
    for m, t in upward:
        print(f"  {m} -> {t}")
    print(
        f"modules in no layer (add their package to LAYERS): {len(unlayered)}",
        *unlayered,
        sep="\n  ",
    )
    print("largest modules:", ", ".join(f"{m} ({n})" for m, n in largest[:5]))
    over = [m for m, n in largest if n > MAX_LINES]
    print(f"over {MAX_LINES} lines: {len(over)}", *over, sep="\n  ")
    return 1 if found or upward or unlayered or over else 0


if __name__ == "__main__":
    raise SystemExit(main())
