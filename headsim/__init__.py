"""headsim: a MuJoCo testbed for vergence-based active stereo vision on humanoid heads."""

from headsim.sim.backend import choose_default_backend

# MuJoCo picks its OpenGL backend when first imported: choose before that.
choose_default_backend()

__version__ = "0.1.0"
