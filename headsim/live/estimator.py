"""The live head's measurement from one frame: image offsets, fixation angles, a position.

Measurement path (no ground truth): each frame's marker centroids in both
images, the encoders latched at its mid-exposure, and the image Jacobian that
the paper's servo measured at rest (px per encoder step, :class:`NeckServo`).
From these, every frame gives

- the *fixation angles* ``q*``: the joint angles (neck yaw, neck pitch, eye)
  at which the target would sit on the goal columns and row,
  ``q* = q_enc - J^-1 e`` (e: image offsets, px);
- a *position estimate*: each camera's line of sight to the target as a
  virtual eye angle ``alpha*_i = alpha_enc - e_i / g_i`` (``g_i``: camera i's
  px per rad of eye motor, from J), then Model 2's eqs. (4), (5) for depth
  and x, the rows for y, and eq. (3) with the neck encoders.  The geometry
  is what the head believes (:class:`HeadKnowledge`: its baseline, neck D-H
  lengths and lines of sight's offsets), as in the at-rest Models 1 and 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from headsim.active.measurement import HeadKnowledge
from headsim.geometry.heads import Neck
from headsim.sim.settings import HeadBelief


@dataclass(frozen=True)
class Offsets:
    """A frame's measurement: image offsets from the goals, px, and what follows from them."""

    error_px: np.ndarray  # (u1 - u10, u2 - u20, (v1 + v2)/2 - v0)
    rows_px: np.ndarray  # (v1 - v10, v2 - v20)
    fixation_rad: np.ndarray  # q*: (neck yaw, neck pitch, eye)
    estimate_world_m: np.ndarray
    estimate_head_m: np.ndarray


class GazeEstimator:
    """Fixation angles and a 3-D position from one frame (see the module docstring).

    ``belief``: the head's believed geometry (baseline, neck D-H lengths, m);
    ``los_offset_m``: each goal column's line of sight's offset from its yaw
    axis, m (:meth:`HeadKnowledge.line_of_sight_offsets`); ``knowledge``: the
    initial directions and kx/ky ratios; ``neck``: the neck's designed layout.  Nothing
    here is the true head.
    """

    def __init__(
        self,
        jacobian_px_per_step: np.ndarray,
        encoder_resolution_rad: float,
        goals_px: tuple[tuple[float, float], tuple[float, float]],
        belief: HeadBelief,
        knowledge: HeadKnowledge | None = None,
        los_offset_m: tuple[float, float] = (0.0, 0.0),
        neck: Neck | None = None,
    ) -> None:
        self.jacobian_per_rad = np.asarray(jacobian_px_per_step, float) / encoder_resolution_rad
        self.belief = belief
        self.los_offset_m = (float(los_offset_m[0]), float(los_offset_m[1]))
        self.goals = np.asarray(goals_px, float)  # ((u10, v10), (u20, v20))
        self.knowledge = knowledge or HeadKnowledge()
        #: The neck's layout (H10), as the head was designed: eq. (1) by default.
        self.neck = neck or Neck()

    def measure(
        self, uv: tuple[tuple[float, float], tuple[float, float]], encoders_rad: np.ndarray
    ) -> Offsets:
        (u1, v1), (u2, v2) = uv
        (u10, v10), (u20, v20) = self.goals
        error = np.array([u1 - u10, u2 - u20, (v1 + v2) / 2 - (v10 + v20) / 2])
        fixation = encoders_rad - np.linalg.solve(self.jacobian_per_rad, error)
        gains = self.jacobian_per_rad[:2, 2]  # du_i / d(eye), px/rad
        eye = encoders_rad[2]
        a1 = eye - error[0] / gains[0] + self.knowledge.alpha_e[0]
        a2 = eye - error[1] / gains[1] + self.knowledge.alpha_e[1]
        t1, t2 = math.tan(a1), math.tan(a2)
        d, (o1, o2) = self.belief.baseline_m, self.los_offset_m
        sec1, sec2 = 1 / math.cos(a1), 1 / math.cos(a2)
        # Model 2's crossing of the (offset) lines of sight, estimators.model2.
        z = (d - o1 * sec1 + o2 * sec2) / (t1 + t2) if t1 + t2 > 1e-9 else math.inf
        x = z * t1 + o1 * sec1 - d / 2
        rows = np.array([v1 - v10, v2 - v20])
        ratio = np.asarray(self.knowledge.kx_over_ky, float)
        # Each camera's distance along its line of sight (L1, L2 of estimators.model2).
        reach = np.array([z * sec1 + o1 * t1, z * sec2 - o2 * t2])
        y = float(np.mean(rows * ratio / np.abs(gains) * reach))
        head = np.array([x, y, z])
        b = self.belief
        world = self.neck.head_to_world(
            head, encoders_rad[0], encoders_rad[1], b.neck_d1_m, b.neck_a2_m
        )
        return Offsets(error, rows, fixation, np.asarray(world, float), head)

    def eye_fixation(self, offsets: Offsets, encoders_rad: np.ndarray) -> float:
        """Eyes alone: the eye angle halfway between the two cameras' fixation angles."""
        gains = self.jacobian_per_rad[:2, 2]
        return float(encoders_rad[2] - np.mean(offsets.error_px[:2] / gains))


__all__ = ["GazeEstimator", "Offsets"]
