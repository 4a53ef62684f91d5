"""The head's joints as commanded and as they truly settle: each motor's command and
the side it last moved from, the joint-error model, and how a settle ends (rad).

Joint errors (``HeadSettings.backlash_rad``, ``count_error``): each motor's
encoder reads its commanded count, while the joint settles (in either mode)
at the command plus a seeded offset within that count and minus half the
backlash on the side it came from.  The true angles are ground truth only.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from headsim.sim.settings import HeadSettings


class SettleOutcome(enum.Enum):
    SETTLED = "settled"
    TIMEOUT = "timeout"
    KINEMATIC = "kinematic"


@dataclass(frozen=True)
class SettleResult:
    """How a settle ended: outcome, physics steps taken, worst joint error (rad)."""

    outcome: SettleOutcome
    steps: int
    max_error_rad: float


class JointLimitError(ValueError):
    """A command outside a joint's range."""


@dataclass
class Commands:
    """What each motor is commanded to, rad, and the side each last moved from."""

    neck_yaw: float = 0.0
    neck_pitch: float = 0.0
    eye: float = 0.0
    #: Ca2's eye motor, on a head with independent eyes.
    eye2: float = 0.0
    pending: set[str] = field(default_factory=set)
    #: Direction each joint last moved in (+1, -1; 0 before any move): backlash side.
    approach: dict[str, float] = field(
        default_factory=lambda: {"neck_yaw": 0.0, "neck_pitch": 0.0, "eye": 0.0, "eye2": 0.0}
    )


#: Index of each motor in the seeded count-error draw.
MOTOR_INDEX = {"neck_yaw": 0, "neck_pitch": 1, "eye": 2, "eye2": 3}
#: The motors of the paper's head.
PAPER_MOTORS = ("neck_yaw", "neck_pitch", "eye")


def joint_offset(settings: HeadSettings, commands: Commands, motor: str, command: float) -> float:
    """True minus commanded angle of a motor's joint, rad (0 on an ideal head)."""
    offset = -0.5 * settings.backlash_rad * commands.approach[motor]
    if settings.count_error:
        resolution = settings.encoder_resolution_rad
        count = round(command / resolution)
        rng = np.random.default_rng(
            [settings.seed, MOTOR_INDEX[motor], count & 0xFFFFFFFF, count < 0]
        )
        offset += float(rng.uniform(-0.5, 0.5)) * resolution
    return offset


def true_targets(
    settings: HeadSettings, commands: Commands, motors: tuple[str, ...] = PAPER_MOTORS
) -> dict[str, float]:
    """Where each of ``motors``' joints truly settles, rad, by motor name."""
    angles = {motor: float(getattr(commands, motor)) for motor in motors}
    if not settings.joint_errors:
        return angles
    return {m: a + joint_offset(settings, commands, m, a) for m, a in angles.items()}


__all__ = [
    "MOTOR_INDEX",
    "Commands",
    "JointLimitError",
    "SettleOutcome",
    "SettleResult",
    "joint_offset",
    "true_targets",
]
