"""The shipped heads as their files declare them, read without MuJoCo (the CLI's help
lists them, and must stay light).

A head file in models/ ships by declaring itself in its MJCF ``<custom>`` block:
``<text name="headsim:description" data="..."/>`` (its one line for the CLI and the
docs) and ``<text name="headsim:mapping.KEY" data="..."/>`` for each key of a
scenario's ``[head.mapping]`` (``cameras``: the two names, space-separated).
:data:`headsim.sim.heads.REGISTRY` builds each head from that.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from xml.etree import ElementTree

#: The head and scene MJCF files: the repository's models/, installed as package data.
MODELS_DIR = Path(str(resources.files("headsim.models")))
#: The prefix of a head file's ``<custom><text>`` entries that headsim reads.
DECLARATION = "headsim:"
#: The paper's head (models/head.xml, which every scene file includes): built in.
PAPER_DESCRIPTION = "the paper's head: 2-DOF neck, one motor counter-yawing both eyes"


def declaration(path: Path) -> dict[str, str]:
    """The ``headsim:`` entries of an MJCF file's ``<custom>`` block (prefix removed);
    empty for a file that declares nothing."""
    root = ElementTree.parse(path).getroot()
    return {
        str(text.get("name"))[len(DECLARATION) :]: str(text.get("data", ""))
        for custom in root.iter("custom")
        for text in custom.iter("text")
        if str(text.get("name", "")).startswith(DECLARATION)
    }


def declared_heads(models: Path) -> dict[str, dict[str, str]]:
    """Every head file in ``models`` that declares a description, by file stem,
    alphabetically: its entries."""
    return {
        path.stem: found
        for path in sorted(models.glob("*.xml"))
        if "description" in (found := declaration(path))
    }


#: The head files of models/ that declare themselves (:func:`declared_heads`).
DECLARED = declared_heads(MODELS_DIR)
#: Each shipped head's one line, for the CLI and the docs: the paper's, then the files'.
SHIPPED: dict[str, str] = {
    "paper": PAPER_DESCRIPTION,
    **{name: found["description"] for name, found in DECLARED.items()},
}

__all__ = [
    "DECLARATION",
    "DECLARED",
    "MODELS_DIR",
    "PAPER_DESCRIPTION",
    "SHIPPED",
    "declaration",
    "declared_heads",
]
