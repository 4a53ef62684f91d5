"""Motors with speed and acceleration limits, driven through MuJoCo's position actuators.

Each motor (neck yaw, neck pitch, the eye motor) has a reference trajectory
``r(t)`` that never exceeds the motor's speed and acceleration limits.  At every
physics step the reference is advanced by one of three laws and written to the
position actuator with velocity and acceleration feed-forward, so the joint
follows it closely while the physics (inertia, damping, the eye coupling)
decides where the joint really is.  Units: rad, rad/s, rad/s^2, s.

Laws (:class:`MotorMode`):
- ``VELOCITY``: ramp to a commanded speed (the Gymnasium action).
- ``TRACK``: reach a goal that moves at a constant velocity, time-optimally
  (bang-bang in acceleration: accelerate at the limit, coast at the speed
  limit, brake at the limit); smooth pursuit and bang-bang saccades use it.
- ``PROFILE``: follow a precomputed minimum-jerk move (a saccade).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from headsim.sim.heads import PAPER, HeadMapping, actuator_coefficients, actuator_on
from headsim.sim.settings import SettingsError

#: The motors in the order of every 3-vector here: (neck yaw, neck pitch, eye).
MOTORS = ("neck_yaw", "neck_pitch", "eye")


def motor_joints(mapping: HeadMapping) -> tuple[str, str, str]:
    """The joint each of :data:`MOTORS` reads: neck yaw, pitch and Ca1's eye."""
    if mapping.neck_yaw is None:
        raise SettingsError("the live head needs a neck yaw joint (head.mapping.neck_yaw)")
    return (mapping.neck_yaw, mapping.neck_pitch, mapping.left_eye)


#: Peak speed and acceleration of a minimum-jerk move of amplitude 1 over time 1.
MIN_JERK_PEAK_SPEED = 1.875
MIN_JERK_PEAK_ACCEL = 10.0 / math.sqrt(3.0)


@dataclass(frozen=True)
class MotorLimits:
    """Speed (rad/s) and acceleration (rad/s^2) limits of one motor."""

    max_speed: float
    max_accel: float

    def __post_init__(self) -> None:
        for name in ("max_speed", "max_accel"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise SettingsError(f"motor {name} must be a finite number > 0, got {value!r}")


class MotorMode(enum.Enum):
    VELOCITY = "velocity"
    TRACK = "track"
    PROFILE = "profile"


def min_jerk_duration(amplitude: float, limits: MotorLimits) -> float:
    """Shortest minimum-jerk move of ``amplitude`` rad within ``limits``, s."""
    a = abs(amplitude)
    return max(
        MIN_JERK_PEAK_SPEED * a / limits.max_speed,
        math.sqrt(MIN_JERK_PEAK_ACCEL * a / limits.max_accel),
    )


def bang_bang_duration(amplitude: float, limits: MotorLimits) -> float:
    """Time-optimal rest-to-rest move of ``amplitude`` rad within ``limits``, s."""
    a, v, acc = abs(amplitude), limits.max_speed, limits.max_accel
    if a <= v * v / acc:  # triangular: the speed limit is never reached
        return 2.0 * math.sqrt(a / acc)
    return a / v + v / acc


def min_jerk(start: float, goal: float, duration: float, t: float) -> tuple[float, float, float]:
    """Position, velocity, acceleration of a minimum-jerk move at time ``t`` after its start."""
    if duration <= 0 or t >= duration:
        return goal, 0.0, 0.0
    s = max(t, 0.0) / duration
    d = goal - start
    pos = start + d * (10 * s**3 - 15 * s**4 + 6 * s**5)
    vel = d * (30 * s**2 - 60 * s**3 + 30 * s**4) / duration
    acc = d * (60 * s - 180 * s**2 + 120 * s**3) / duration**2
    return pos, vel, acc


@dataclass
class _Motor:
    limits: MotorLimits
    low: float
    high: float
    ref: float = 0.0
    vel: float = 0.0
    acc: float = 0.0
    mode: MotorMode = MotorMode.VELOCITY
    speed: float = 0.0  # VELOCITY
    goal: float = 0.0  # TRACK: goal at goal_time, moving at goal_vel
    goal_vel: float = 0.0
    goal_time: float = 0.0
    start: float = 0.0  # PROFILE
    start_time: float = 0.0
    duration: float = 0.0


class MotorDriver:
    """The three motors of a head in a MuJoCo model: rate-limited references to the actuators.

    With independent eyes the eye motor's reference drives both eyes' actuators (the
    counter-yaw of the paper's one motor).  The actuators are retuned to a stiff critically damped servo of natural
    frequency ``bandwidth_hz`` on each joint's effective inertia (at the home
    pose), so that with feed-forward the joints follow their references to a
    small fraction of a degree even at the acceleration limits.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        limits: tuple[MotorLimits, MotorLimits, MotorLimits],
        bandwidth_hz: float = 20.0,
        mapping: HeadMapping = PAPER.mapping,
    ) -> None:
        self.model, self.data = model, data
        joints = motor_joints(mapping)
        self._qadr = [int(model.joint(j).qposadr[0]) for j in joints]
        omega = 2 * math.pi * bandwidth_hz
        mujoco.mj_forward(model, data)
        #: (actuator, gear: its length per unit of the motor's reference, velocity and
        #: acceleration feed-forward) per motor.
        self._act: list[list[tuple[int, float, float, float]]] = []
        for motor, pairs in enumerate(self._driven(mapping, joints)):
            tuned = []
            for act, gear, row in pairs:
                mass = self._inertia(row)
                if motor == 2 and mapping.eyes == "coupled":  # one motor carries both eyes
                    mass = sum(
                        self._inertia(self._joint_row(j))
                        for j in (mapping.left_eye, mapping.right_eye)
                    )
                kp, kv = mass * omega**2, 2.0 * mass * omega
                model.actuator_gainprm[act, 0] = kp
                model.actuator_biasprm[act, :3] = (0.0, -kp, -kv)
                model.actuator_forcelimited[act] = 0
                tuned.append((act, gear, kv / kp, 1.0 / omega**2))
            self._act.append(tuned)
        self.motors: list[_Motor] = []
        for lim, j in zip(limits, joints, strict=True):
            low, high = model.joint(j).range
            self.motors.append(_Motor(lim, float(low), float(high)))
        self.sync()

    def _joint_row(self, joint: str) -> np.ndarray:
        row = np.zeros(self.model.nv)
        row[int(self.model.joint(joint).dofadr[0])] = 1.0
        return row

    def _driven(
        self, mapping: HeadMapping, joints: tuple[str, str, str]
    ) -> list[list[tuple[int, float, np.ndarray]]]:
        """(actuator, gear, its length's row over the dofs) for each motor.  The eye
        motor's reference is each eye's inward angle (the counter-yaw): with independent
        eyes both eyes' actuators follow it; with version and vergence the vergence
        follows twice it and the version holds zero (gear 0)."""
        model = self.model
        driven = [[(actuator_on(model, j), 1.0, self._joint_row(j))] for j in joints[:2]]
        if mapping.version is not None and mapping.vergence is not None:
            eye = []
            for name, gear in ((mapping.version, 0.0), (mapping.vergence, 2.0)):
                act = int(model.actuator(name).id)
                row = np.zeros(model.nv)
                for joint, coef in actuator_coefficients(model, act).items():
                    row[int(model.jnt_dofadr[joint])] += coef
                eye.append((act, gear, row))
            driven.append(eye)
        else:
            eye_joints = [joints[2]] + ([mapping.right_eye] if mapping.independent else [])
            driven.append([(actuator_on(model, j), 1.0, self._joint_row(j)) for j in eye_joints])
        for pairs in driven:
            for act, _, _ in pairs:
                if act < 0:
                    raise SettingsError("a motor's joint has no position actuator to drive it")
        return driven

    def _inertia(self, row: np.ndarray) -> float:
        """The inertia an actuator of length ``row . q`` moves, at the current pose: a joint's
        diagonal entry of the joint-space inertia; a tendon's 1 / (J M^-1 J^T)."""
        full = np.zeros((self.model.nv, self.model.nv))
        mujoco.mj_fullM(self.model, self.data, full)
        if np.count_nonzero(row) == 1:
            dof = int(np.flatnonzero(row)[0])
            return float(full[dof, dof])
        return 1.0 / float(row @ np.linalg.solve(full, row))

    def sync(self) -> None:
        """Start the references where the joints are, at rest."""
        for motor, adr in zip(self.motors, self._qadr, strict=True):
            motor.ref, motor.vel, motor.acc = float(self.data.qpos[adr]), 0.0, 0.0
            motor.mode, motor.speed = MotorMode.VELOCITY, 0.0
        self._write()

    # -- commands ----------------------------------------------------------
    def set_velocity(self, index: int, speed: float) -> None:
        """Ramp motor ``index`` to ``speed`` rad/s (clipped to its limit)."""
        motor = self.motors[index]
        motor.mode = MotorMode.VELOCITY
        motor.speed = float(np.clip(speed, -motor.limits.max_speed, motor.limits.max_speed))

    def track(self, index: int, goal: float, goal_vel: float, goal_time: float) -> None:
        """Reach ``goal + goal_vel (t - goal_time)`` time-optimally and follow it."""
        motor = self.motors[index]
        motor.mode = MotorMode.TRACK
        motor.goal, motor.goal_vel, motor.goal_time = float(goal), float(goal_vel), float(goal_time)

    def profile(self, index: int, goal: float, start_time: float, duration: float) -> None:
        """A minimum-jerk move from the present reference to ``goal`` over ``duration`` s."""
        motor = self.motors[index]
        motor.mode = MotorMode.PROFILE
        motor.start, motor.goal = motor.ref, float(np.clip(goal, motor.low, motor.high))
        motor.start_time, motor.duration = float(start_time), float(duration)

    # -- stepping ----------------------------------------------------------
    def advance(self, time_s: float, dt: float) -> None:
        """Advance every reference by ``dt`` to ``time_s + dt`` and write the actuators."""
        for motor in self.motors:
            lim = motor.limits
            if motor.mode is MotorMode.PROFILE:
                pos, vel, acc = min_jerk(
                    motor.start, motor.goal, motor.duration, time_s + dt - motor.start_time
                )
                motor.ref, motor.vel, motor.acc = pos, vel, acc
                continue
            if motor.mode is MotorMode.VELOCITY:
                wanted = motor.speed
            else:
                goal_now = motor.goal + motor.goal_vel * (time_s - motor.goal_time)
                error = goal_now - motor.ref
                # The fastest approach that can still brake at the limit, plus the goal's own speed.
                approach = math.copysign(
                    min(math.sqrt(2.0 * lim.max_accel * abs(error)), abs(error) / dt), error
                )
                wanted = motor.goal_vel + approach
            wanted = min(max(wanted, -lim.max_speed), lim.max_speed)
            dv = min(max(wanted - motor.vel, -lim.max_accel * dt), lim.max_accel * dt)
            motor.acc = dv / dt
            motor.vel += dv
            motor.ref += motor.vel * dt
            if not motor.low <= motor.ref <= motor.high:
                motor.ref = min(max(motor.ref, motor.low), motor.high)
                motor.vel, motor.acc = 0.0, 0.0
        self._write()

    def _write(self) -> None:
        for motor, actuators in zip(self.motors, self._act, strict=True):
            for act, gear, fv, fa in actuators:
                self.data.ctrl[act] = gear * (motor.ref + fv * motor.vel + fa * motor.acc)

    @property
    def feeds(self) -> tuple[tuple[tuple[int, float, float, float], ...], ...]:
        """Per motor, each actuator it drives: (actuator id, gear, velocity feed-forward s,
        acceleration feed-forward s^2), as tuned for this model."""
        return tuple(tuple(pairs) for pairs in self._act)

    @property
    def references(self) -> np.ndarray:
        """(3,) reference positions, rad."""
        return np.array([m.ref for m in self.motors])

    @property
    def moving(self) -> bool:
        """Whether any reference is still moving."""
        return any(abs(m.vel) > 1e-9 for m in self.motors)
