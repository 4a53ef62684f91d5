"""Heads in lockstep over arrays: N live heads that advance together.

Joint commands, motor references, encoder readings and frames are arrays over heads
(:class:`LockstepHeads`).  A step advances every head's motors in numpy
(:class:`~headsim.lockstep.motors.VelocityMotors`, the live head's law term for term),
their physics in one MuJoCo batch rollout (``mujoco.batch``: the classic path's
``mj_step`` s, bit for bit), and draws both eyes of every head through one OpenGL
context (:class:`~headsim.lockstep.opengl.ViewRenderer`, the classic renderer's
pixels), finished with each head's own noise streams.  Marker centroids are found over
the whole stack of images (:func:`~headsim.lockstep.detect.find_markers_stacked`,
``find_marker``'s answers).  No thread and no :class:`~headsim.sim.simulator.HeadSim`
per head.  The classic single head (:class:`headsim.live.head.LiveHead`) stays the
reference; tests/lockstep compares the two.
"""

from headsim.lockstep.detect import colour_weight_u8, find_markers_stacked
from headsim.lockstep.heads import Frames, LockstepHeads
from headsim.lockstep.motors import VelocityMotors
from headsim.lockstep.opengl import EyeView, ViewRenderer

__all__ = [
    "EyeView",
    "Frames",
    "LockstepHeads",
    "VelocityMotors",
    "ViewRenderer",
    "colour_weight_u8",
    "find_markers_stacked",
]
