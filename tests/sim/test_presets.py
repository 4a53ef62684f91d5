"""The light list of preset names is the settings' list of presets."""

from __future__ import annotations

from headsim.sim.presets import PRESET_NAMES
from headsim.sim.settings import PRESETS, preset


def test_the_names_are_the_presets() -> None:
    assert tuple(PRESETS) == PRESET_NAMES
    for name in PRESET_NAMES:
        assert preset(name).cameras[0].width == 640
