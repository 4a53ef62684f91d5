"""Count the pure forwarding functions in the package: a def whose body (after its docstring)
is one ``return f(...)`` that passes the def's own parameters through.

``strict``: the call's arguments are exactly the parameters (``self``/``cls`` aside), each a
bare name, nothing added.  ``loose``: every parameter is passed as a bare name, and the call
may add other arguments (constants, attributes, expressions); a def without parameters counts
too.  The closing notes quote both.

    python tools/forwarders.py [--loose] [--list] [ROOT]
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "headsim"


def _parameters(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> list[str]:
    a = fn.args
    names = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
    names += [f"*{a.vararg.arg}"] if a.vararg else []
    names += [f"**{a.kwarg.arg}"] if a.kwarg else []
    return [n for n in names if n not in ("self", "cls")]


def _passed(call: ast.Call) -> tuple[list[str], bool]:
    """The bare names the call passes, and whether it passes anything else."""
    names, other = [], False
    for arg in call.args:
        if isinstance(arg, ast.Name):
            names.append(arg.id)
        elif isinstance(arg, ast.Starred) and isinstance(arg.value, ast.Name):
            names.append(f"*{arg.value.id}")
        else:
            other = True
    for kw in call.keywords:
        if isinstance(kw.value, ast.Name):
            names.append(kw.value.id if kw.arg else f"**{kw.value.id}")
        else:
            other = True
    return names, other


def forwards_to(fn: ast.FunctionDef | ast.AsyncFunctionDef, loose: bool) -> str | None:
    """What ``fn`` forwards to (None: it is not a pure forwarder)."""
    body = fn.body
    first = body[0] if body else None
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
        body = body[1:]
    if len(body) != 1 or not isinstance(body[0], ast.Return):
        return None
    call = body[0].value
    if not isinstance(call, ast.Call):
        return None
    names, other = _passed(call)
    parameters = _parameters(fn)
    held = (
        set(parameters) <= set(names)
        if loose
        else not other and sorted(names) == sorted(parameters)
    )
    return ast.unparse(call.func) if held else None


def forwarders(root: Path, loose: bool) -> list[str]:
    """``path:line name -> target`` of each pure forwarder under ``root``."""
    found = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                target = forwards_to(node, loose)
                if target is not None:
                    found.append(
                        f"{path.relative_to(root.parent)}:{node.lineno} {node.name} -> {target}"
                    )
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", type=Path, default=ROOT)
    parser.add_argument("--loose", action="store_true")
    parser.add_argument("--list", action="store_true")
    args = parser.parse_args()
    found = forwarders(args.root.resolve(), args.loose)
    if args.list:
        print("\n".join(found))
    print(f"{len(found)} pure forwarding functions ({'loose' if args.loose else 'strict'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
