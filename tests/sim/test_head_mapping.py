"""A head given as data (an MJCF built from scratch with MjSpec and its mapping), with real
MuJoCo: its design is read from the model, and the simulator finds every joint, camera
and motor through the mapping alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from heads_builder import BuiltHead, build_head

from headsim.sim import heads
from headsim.sim.model import design, on_head
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim

EXACT = 1e-12


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> BuiltHead:
    return build_head(tmp_path_factory.mktemp("head") / "head.xml")


def head_model(built: BuiltHead) -> heads.HeadModel:
    return heads.HeadModel("never_seen", built.path, built.mapping)


def test_design_is_the_built_lengths(built: BuiltHead) -> None:
    designed = design(head_model(built))
    assert designed.baseline_m == pytest.approx(0.10, abs=EXACT)
    assert designed.neck_d1_m == pytest.approx(0.15, abs=EXACT)
    assert designed.neck_a2_m == pytest.approx(0.07, abs=EXACT)


def test_other_lengths_are_read_too(tmp_path: Path) -> None:
    other = build_head(tmp_path / "other.xml", baseline_m=0.062, d1_m=0.21, a2_m=0.035)
    designed = design(head_model(other))
    assert (designed.baseline_m, designed.neck_d1_m, designed.neck_a2_m) == pytest.approx(
        (0.062, 0.21, 0.035), abs=EXACT
    )


def test_simulator_places_the_cameras_and_turns_each_eye_on_its_own(built: BuiltHead) -> None:
    settings = on_head(HeadSettings(), head_model(built))
    assert settings.baseline_m == pytest.approx(0.10, abs=EXACT)
    with HeadSim(settings=settings) as sim:
        assert sim.head_from_camera(1)[:3, 3] == pytest.approx([-0.05, 0.0, 0.0], abs=1e-9)
        assert sim.head_from_camera(2)[:3, 3] == pytest.approx([0.05, 0.0, 0.0], abs=1e-9)
        step = settings.encoder_resolution_rad
        for left, right in ((0.1, 0.2), (0.0, -0.15), (0.25, 0.0)):
            sim.command(eye=left, eye2=right)
            sim.settle()
            truth = sim.true_joint_angles()
            assert truth["head:port_pan"] == pytest.approx(left, abs=1e-6)
            assert truth["head:starboard_pan"] == pytest.approx(right, abs=1e-6)
            assert sim.eye_encoders() == pytest.approx((left, right), abs=step)
            # Positive is inward: Ca1's optical axis turns to H's +x, Ca2's to -x.
            z1 = sim.head_from_camera(1)[:3, 2]
            z2 = sim.head_from_camera(2)[:3, 2]
            assert z1 == pytest.approx([np.sin(left), 0.0, np.cos(left)], abs=1e-6)
            assert z2 == pytest.approx([-np.sin(right), 0.0, np.cos(right)], abs=1e-6)


def test_each_motor_drives_only_its_eye(built: BuiltHead) -> None:
    settings = on_head(HeadSettings(), head_model(built))
    with HeadSim(settings=settings) as sim:
        sim.command(eye=0.0, eye2=0.0)
        sim.settle()
        sim.command(eye2=0.3)
        sim.settle()
        left, right = sim.eye_encoders()
        assert left == pytest.approx(0.0, abs=settings.encoder_resolution_rad)
        assert right == pytest.approx(0.3, abs=settings.encoder_resolution_rad)
