"""Hooks that campaign files name: a function filed under a name in a table."""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

F = TypeVar("F", bound=Callable[..., object])


def registrar(table: dict[str, F]) -> Callable[[str], Callable[[F], F]]:
    """A decorator factory: ``@hook("name")`` files the function under ``name`` in ``table``,
    the name the files use, and returns it unchanged."""

    def hook(name: str) -> Callable[[F], F]:
        def register(function: F) -> F:
            table[name] = function
            return function

        return register

    return hook


__all__ = ["registrar"]
