"""headsim's version, declared once and imported by nothing else in the package: the
wheel's metadata (pyproject.toml), ``headsim.__version__``, ``headsim --version`` and
results.json all read it from here, so no module imports the package root for it."""

__version__ = "0.1.0"
