"""Tables V/VI with the one calibration: the active methods share their images honestly."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge
from headsim.active.model2 import measure_model2
from headsim.sim.settings import preset
from headsim.sim.simulator import HeadSim
from headsim.studies import paper_tables
from headsim.studies.calibrations import zoom_fixed_points
from headsim.studies.methods import TARGET
from headsim.studies.targets import table_targets


def test_a_method_computed_from_shared_images_equals_its_own_measurement() -> None:
    # A noise-free head renders the same images for the same eye steps, so each
    # active method measured on its own must give exactly what it computes from
    # the images the image-centre servo took (the knowledges differ in v0, kx/ky).
    head = preset("paper", seed=0)
    knowledges = {
        "active_centre": HeadKnowledge(alpha_e=(0.0578, -0.0254)),
        "active_v_known": HeadKnowledge(alpha_e=(0.0578, -0.0254), v0=(306.3, 197.3)),
        "active_extended": HeadKnowledge(
            alpha_e=(0.0578, -0.0254), v0=(306.0, 197.0), kx_over_ky=(1.024, 1.02)
        ),
    }
    with HeadSim("default", head) as sim:
        p_head = table_targets(2)[1]
        sim.set_body_pose(TARGET.name, sim.transform_points(p_head, "head", "world")[0])
        sim.move(eye=0.0)
        shared = measure_model2(sim, EyeServo(sim), TARGET, knowledges["active_centre"])
        assert shared.ok, shared.status
        for knowledge in knowledges.values():
            sim.move(eye=0.0)
            own = measure_model2(sim, EyeServo(sim), TARGET, knowledge)
            assert own.ok, own.status
            computed = paper_tables.recompute(sim.settings, shared, knowledge)
            np.testing.assert_allclose(computed, own.estimate_head_m, rtol=0, atol=1e-12)
        # The v0 the methods differ by moves the estimate: the check could fail.
        centre = paper_tables.recompute(sim.settings, shared, knowledges["active_centre"])
        v_known = paper_tables.recompute(sim.settings, shared, knowledges["active_v_known"])
        assert np.linalg.norm(centre - v_known) > 1e-4


def test_the_calibration_must_servo_on_the_image_centre() -> None:
    stored = HeadKnowledge(alpha_e=(0.05, -0.02), u0=(300.0, 320.0))
    with pytest.raises(ValueError, match="image centre"):
        paper_tables.active_knowledge(stored, None)  # type: ignore[arg-type]


def test_the_fixed_points_found_again_on_their_own_head_are_the_calibrations() -> None:
    # measure_paired takes them from the FixedPoint on the head it was made on: that
    # holds only because finding them again gives the same images and answer.
    from headsim.studies.methods import StudyConfig

    settings = preset("paper")
    config = StudyConfig.quick(calibration_targets=4)
    fixed = paper_tables.fixed_point_calibration(settings, config)
    again = zoom_fixed_points(settings, config)
    assert fixed.settings == settings and fixed.seed == config.seed
    assert again.principal_px == fixed.principal.principal_px
    assert again.renders == fixed.principal.renders
