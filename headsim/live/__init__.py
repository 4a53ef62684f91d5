"""A live head: time, motors with limits, moving targets, gaze behaviours (issue 15)."""

from headsim.live.head import Frame, LiveConfig, LiveHead
from headsim.live.motors import MotorDriver, MotorLimits
from headsim.live.paths import Jump, RandomWalk, Sinusoid, Static, Throw, Visibility, Waypoints

__all__ = [
    "Frame",
    "Jump",
    "LiveConfig",
    "LiveHead",
    "MotorDriver",
    "MotorLimits",
    "RandomWalk",
    "Sinusoid",
    "Static",
    "Throw",
    "Visibility",
    "Waypoints",
]
