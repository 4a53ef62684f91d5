"""The head presets' names, light enough for the command line's ``--help`` (no numpy).

``headsim.sim.settings.PRESETS`` maps each to its settings; a test keeps the two in step.
"""

from __future__ import annotations

PRESET_NAMES = ("ideal", "paper", "realistic")
