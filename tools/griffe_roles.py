"""Griffe extension: the docstrings' Sphinx roles as cross-references on the API page.

headsim's docstrings are Sphinx style (``:func:`run```, ``:class:`~a.B```) with Markdown
text; mkdocstrings renders Markdown and would show the roles raw. ``mkdocs.yml`` loads
this file (``extensions`` of the Python handler): each role becomes an optional
cross-reference to the object it names, resolved in the docstring's scope as Python
would resolve the name there, a link where the object is on the site and plain code
where it is not. A reST literal-block marker (``text::`` before an indented block)
becomes ``text:`` (the indented block is already code in Markdown).
"""

from __future__ import annotations

import re
from html import escape
from typing import Any

from griffe import Alias, Extension, Object

#: ``:role:`target``` or ``:role:`title <target>```; ``~`` shows the last part only.
ROLE = re.compile(
    r":(?:py:)?(?:class|func|meth|mod|data|attr|exc|obj|const|type):"
    r"`(?:(?P<title>[^`<]*?)\s*<(?P<target>[^`>]+)>|(?P<bare>[^`]+))`"
)
#: A paragraph that ends in ``::`` before a blank line (reST's literal block).
LITERAL_MARKER = re.compile(r"(?<=\S)::(?=\n[ \t]*\n)")


def resolve(name: str, scope: Object | Alias | None) -> str:
    """The full path ``name`` means in ``scope``: its first part looked up in the scope
    and each enclosing one (an imported name through its import); else ``name``."""
    first, _, rest = name.partition(".")
    while scope is not None:
        member = scope.members.get(first) if hasattr(scope, "members") else None
        if member is not None:
            base = member.target_path if isinstance(member, Alias) else member.path
            return f"{base}.{rest}" if rest else base
        scope = scope.parent
    return name


def rewrite(text: str, scope: Object | Alias) -> str:
    """``text`` with each role an optional cross-reference and each ``::`` a ``:``."""

    def one(match: re.Match[str]) -> str:
        target = (match["target"] or match["bare"]).strip()
        shown = match["title"]
        if target.startswith("~"):
            target = target[1:]
            shown = shown or target.rsplit(".", 1)[-1]
        path = resolve(target.lstrip("."), scope)
        return (
            f'<autoref identifier="{escape(path)}" optional>'
            f"<code>{escape(shown or target)}</code></autoref>"
        )

    return LITERAL_MARKER.sub(":", ROLE.sub(one, text))


class SphinxRoles(Extension):
    """Rewrites every docstring once the object tree is complete."""

    def on_object(self, *, obj: Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = rewrite(obj.docstring.value, obj)
