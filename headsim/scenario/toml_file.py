"""Parsing a scenario file: TOML 1.0, with every failure a one-line :class:`ScenarioError`.

Syntax errors, nesting deeper than :data:`MAX_NESTING`, integers of more than
:data:`MAX_DIGITS` digits and non-UTF-8 text are refused naming the line.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import Any

from headsim.scenario.tables import ScenarioError

#: Deepest nesting of arrays and inline tables a scenario file may have.
MAX_NESTING = 50


#: Most digits an integer in a scenario file may have (Python's int() limit is 4300).
MAX_DIGITS = 4300


def read_toml(path: Path) -> dict[str, Any]:
    """Parse a TOML file; any failure (syntax, nesting, huge integers, encoding) is a
    :class:`ScenarioError` naming the line.  A UTF-8 byte-order mark is allowed."""
    source = str(path)
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = path.read_bytes()[: err.start].count(b"\n") + 1
        raise ScenarioError(source, "", f"line {line}: not UTF-8 text ({err.reason})") from err
    except OSError as err:
        raise ScenarioError(source, "", f"cannot be read: {err.strerror or err}") from err
    deep = deep_line(text)
    if deep:
        raise ScenarioError(
            source, "", f"arrays or inline tables nested too deeply{deep}",
            f"at most {MAX_NESTING} levels",
        )  # fmt: skip
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        last = text.count("\n") + (0 if text.endswith("\n") else 1)
        reason = str(err).replace("(at end of document)", f"(at line {last}, the end of the file)")
        raise ScenarioError(source, "", f"not valid TOML: {reason}", "TOML 1.0") from err
    except RecursionError as err:
        raise ScenarioError(source, "", "nested too deeply for the TOML parser") from err
    except ValueError as err:  # int() refuses more than 4300 digits
        line = _long_number_line(text)
        raise ScenarioError(
            source, "", f"{line}a number with too many digits ({err})",
            f"integers of at most {MAX_DIGITS} digits",
        ) from err  # fmt: skip


def text_or_empty(path: Path) -> str:
    try:
        return path.read_bytes().decode("utf-8-sig", errors="replace")
    except OSError:
        return ""


def deep_line(text: str) -> str:
    """``" at line N"`` where brackets nest deeper than :data:`MAX_NESTING`, else ``""``.

    Counts ``[`` and ``{`` outside strings and comments; a table header's ``[[``
    adds at most two levels, far below the limit.
    """
    depth, line, quote, comment = 0, 1, "", False
    for index, char in enumerate(text):
        if char == "\n":
            line, comment = line + 1, False
            if quote in ('"', "'"):
                quote = ""
            continue
        if comment:
            continue
        if quote:
            if char == quote[0] and not (quote == '"' and text[index - 1] == "\\"):
                quote = ""
            continue
        if char == "#":
            comment = True
        elif char in "\"'":
            quote = char
        elif char in "[{":
            depth += 1
            if depth > MAX_NESTING:
                return f" at line {line}"
        elif char in "]}":
            depth = max(depth - 1, 0)
    return ""


def _long_number_line(text: str) -> str:
    match = re.search(rf"[0-9_]{{{MAX_DIGITS + 1},}}", text)
    if match is None:
        return ""
    return f"line {text.count(chr(10), 0, match.start()) + 1}: "
