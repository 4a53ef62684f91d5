"""The simulated head: MJCF names, settings, model building, optics, rendering, the simulator,
and the settings as the exact forward model sees them (``forward``).

``HeadSim`` is importable from here; it loads MuJoCo only when first used, so
that ``headsim.sim.settings`` stays light.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from headsim.sim.simulator import HeadSim

__all__ = ["HeadSim"]


def __getattr__(name: str) -> Any:
    if name == "HeadSim":
        from headsim.sim.simulator import HeadSim

        return HeadSim
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
