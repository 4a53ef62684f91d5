"""The joint-error model: where each joint truly settles for its command (pure, exact)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.sim.joints import Commands, joint_offset, true_targets
from headsim.sim.settings import HeadSettings


def test_an_ideal_head_settles_exactly_at_its_commands() -> None:
    commands = Commands(neck_yaw=0.1, neck_pitch=-0.2, eye=0.05)
    commands.approach.update(neck_yaw=1.0, eye=-1.0)
    assert true_targets(HeadSettings(), commands) == {
        "neck_yaw": 0.1,
        "neck_pitch": -0.2,
        "eye": 0.05,
    }


def test_backlash_leaves_each_joint_half_the_play_short_on_the_side_it_came_from() -> None:
    settings = replace(HeadSettings(), backlash_rad=0.002)
    commands = Commands(neck_yaw=0.1, neck_pitch=-0.2, eye=0.05)
    commands.approach.update(neck_yaw=1.0, neck_pitch=-1.0, eye=0.0)
    true = true_targets(settings, commands)
    assert true["neck_yaw"] == pytest.approx(0.1 - 0.001, abs=1e-15)
    assert true["neck_pitch"] == pytest.approx(-0.2 + 0.001, abs=1e-15)
    assert true["eye"] == 0.05  # never moved: no side yet


def test_the_count_error_lies_within_the_count_and_is_the_same_for_the_same_count() -> None:
    settings = replace(HeadSettings(), count_error=True, seed=7)
    resolution = settings.encoder_resolution_rad
    commands = Commands()
    offsets = {
        motor: [joint_offset(settings, commands, motor, k * resolution) for k in range(-50, 50)]
        for motor in ("neck_yaw", "neck_pitch", "eye")
    }
    for values in offsets.values():
        assert np.all(np.abs(values) <= 0.5 * resolution)
        assert np.std(values) > 0.1 * resolution  # spread over the count, not on it
    # Seeded per motor and count: again the same, another motor differs.
    again = [joint_offset(settings, commands, "eye", k * resolution) for k in range(-50, 50)]
    assert again == offsets["eye"]
    assert offsets["eye"] != offsets["neck_yaw"]
