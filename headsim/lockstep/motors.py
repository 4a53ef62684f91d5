"""The live head's motors in velocity mode, over arrays of heads.

:class:`headsim.live.motors.MotorDriver`'s ``VELOCITY`` law, term for term in the same
order (so the same floating-point results): each reference ramps to its commanded speed
within the motor's acceleration limit and stops at the joint's range.  Rows are heads;
columns the motors (neck yaw, neck pitch, eye).
"""

from __future__ import annotations

import numpy as np

from headsim.live.motors import MotorLimits


class VelocityMotors:
    """Reference position, speed and acceleration of ``n`` heads' three motors (rad,
    rad/s, rad/s^2), and each motor's commanded speed."""

    def __init__(self, n: int, limits: tuple[MotorLimits, MotorLimits, MotorLimits]) -> None:
        self.max_speed = np.array([lim.max_speed for lim in limits], float)
        self.max_accel = np.array([lim.max_accel for lim in limits], float)
        self.ref = np.zeros((n, 3))
        self.vel = np.zeros((n, 3))
        self.acc = np.zeros((n, 3))
        self.speed = np.zeros((n, 3))
        self.low = np.full((n, 3), -np.inf)
        self.high = np.full((n, 3), np.inf)

    def sync(
        self, ids: np.ndarray, joints_rad: np.ndarray, low: np.ndarray, high: np.ndarray
    ) -> None:
        """Start ``ids``' references at ``joints_rad`` (m, 3), at rest, within [low, high]."""
        self.ref[ids] = joints_rad
        self.vel[ids] = 0.0
        self.acc[ids] = 0.0
        self.speed[ids] = 0.0
        self.low[ids] = low
        self.high[ids] = high

    def set_speed(self, ids: np.ndarray, speeds_rad_s: np.ndarray) -> None:
        """Ramp ``ids``' motors to ``speeds_rad_s`` (m, 3), clipped to the speed limits."""
        self.speed[ids] = np.clip(speeds_rad_s, -self.max_speed, self.max_speed)

    def ramp(
        self, ids: np.ndarray, speeds_rad_s: np.ndarray, dt: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance ``ids``' references by one step of ``dt`` s per row of ``speeds_rad_s``
        (nstep, m, 3): the commanded speed during each step.  Returns each step's
        (ref, vel, acc), each (nstep, m, 3), and keeps the last."""
        nstep = len(speeds_rad_s)
        refs, vels, accs = (np.empty((nstep, len(ids), 3)) for _ in range(3))
        ref, vel = self.ref[ids], self.vel[ids]
        acc = self.acc[ids]
        low, high = self.low[ids], self.high[ids]
        step = self.max_accel * dt
        for j in range(nstep):
            wanted = np.minimum(np.maximum(speeds_rad_s[j], -self.max_speed), self.max_speed)
            dv = np.minimum(np.maximum(wanted - vel, -step), step)
            acc = dv / dt
            vel = vel + dv
            ref = ref + vel * dt
            out = (ref < low) | (ref > high)
            if out.any():
                ref = np.minimum(np.maximum(ref, low), high)
                vel[out] = 0.0
                acc[out] = 0.0
            refs[j], vels[j], accs[j] = ref, vel, acc
        self.ref[ids], self.vel[ids], self.acc[ids] = ref, vel, acc
        return refs, vels, accs


__all__ = ["VelocityMotors"]
