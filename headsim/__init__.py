"""headsim: a MuJoCo testbed for vergence-based active stereo vision on humanoid heads."""

__version__ = "0.1.0"
