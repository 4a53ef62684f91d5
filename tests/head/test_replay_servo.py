"""The quick start recorded to MCAP with every look of its servo (windows as Image with
CameraInfo.roi, previews binned), and its Model 2 replayed from the file alone: the same
estimates, bit for bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from headsim.active.events import PhaseStarted
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge
from headsim.active.model2 import measure_model2
from headsim.head.mcap_log import read_grabs
from headsim.head.replay import ReplayDiverged
from headsim.head.replay_servo import ReplayServoHead
from headsim.runs.context import head, model2_config, servo_config
from headsim.runs.events import Hub, Stamp
from headsim.runs.mcap_run import McapRun
from headsim.runs.runner import run_scenario
from headsim.runs.targets import marker_target
from headsim.scenario.loading import load_scenario

pytestmark = pytest.mark.e2e


class _Knowledge:
    """What the head knew when each phase began."""

    def __init__(self) -> None:
        self.by_phase: dict[str, HeadKnowledge] = {}

    def notify(self, event: object, at: Stamp) -> None:
        if isinstance(event, PhaseStarted):
            self.by_phase[event.name] = event.knowledge


def test_the_quick_starts_model2_replays_from_its_mcap_bit_for_bit(tmp_path: Path) -> None:
    scenario = load_scenario("quickstart", fast=True)
    path = tmp_path / "quickstart.mcap"
    recording, knowledge = McapRun(path), _Knowledge()
    try:
        result = run_scenario(scenario, [recording, knowledge])
    finally:
        recording.close()
    assert result.failures == ()
    grabs = read_grabs(path)
    assert len(grabs) == recording.images
    measured = [g for g in grabs if g.phase == "measurement"]
    assert {g.phase for g in grabs} == {"calibration", "measurement"}
    # The servo's windows and previews are in the file, each with its roi or binning.
    windows = [g for g in measured if g.window is not None]
    previews = [g for g in measured if g.binning > 1]
    assert windows and previews
    for g in windows:
        assert g.window is not None
        assert g.image.shape[:2] == (g.window.height, g.window.width)
    for g in previews:
        assert g.image.shape[0] == scenario.settings.cameras[g.camera - 1].height // g.binning

    with head(Hub(), "default", scenario) as sim_head:  # the head's joint ranges
        limits = {m: sim_head.joint_range(m) for m in sim_head.motors}
    replay = ReplayServoHead(measured, scenario.settings, limits)
    servo = EyeServo(replay, servo_config(scenario))
    config = model2_config(scenario)
    replayed = [
        measure_model2(
            replay, servo, marker_target(t.name, t.body), knowledge.by_phase["measurement"], config
        )
        for t in scenario.scene.targets
    ]
    assert replay.remaining == 0  # every recorded look served, none asked beyond
    assert len(replayed) == len(result.records) == 3
    for record, again in zip(result.records, replayed, strict=True):
        first = record.measurement
        assert again.ok and first.ok
        assert np.array_equal(first.estimate_head_m, again.estimate_head_m)
        assert np.array_equal(first.covariance_head_m2, again.covariance_head_m2)
        assert first.details == again.details
        assert first.renders == again.renders
        assert np.isnan(again.truth_head_m).all()  # a replay has no truth to score by

    # A procedure that strays from the recording is told where.
    first_look = measured[0]
    assert first_look.binning > 1  # the first target is found in a preview
    strayed = ReplayServoHead(measured, scenario.settings, limits)
    strayed.command_eye_steps(strayed.eye_encoder_steps() + 7)
    with pytest.raises(ReplayDiverged, match="image 1: eye at"):
        strayed.render_preview(first_look.camera, first_look.binning)
    with pytest.raises(ReplayDiverged, match=f"binning 1; .* binning {first_look.binning}"):
        ReplayServoHead(measured, scenario.settings, limits).render(first_look.camera)
