"""A study's head as a preset, and what it is told as a calibration file the runner reads."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from headsim.active.calibration_file import read_calibration
from headsim.active.measurement import HeadKnowledge
from headsim.sim.settings import PRESETS, CameraSettings, HeadSettings, paper_head
from headsim.studies.scenario_runs import knowledge_file, preset_of, scenario_with_head


@pytest.mark.parametrize("name", list(PRESETS))
def test_each_presets_head_is_found_by_its_name(name: str) -> None:
    assert preset_of(PRESETS[name](seed=3)) == name


def test_a_head_that_is_no_preset_is_refused() -> None:
    with pytest.raises(ValueError, match=r"describe it in the scenario's \[head\]"):
        preset_of(replace(paper_head(), baseline_m=0.2))


@pytest.mark.parametrize(
    "knowledge",
    [
        HeadKnowledge(),
        HeadKnowledge(
            alpha_e=(0.0578123456789, -0.0254),
            v0=(231.25, None),
            kx_over_ky=(1.0013, 0.9987),
            u0=(None, 322.5),
            los_offset_m=(0.0011, -0.0004),
        ),
    ],
)
def test_the_file_tells_the_head_exactly_its_knowledge(
    tmp_path: Path, knowledge: HeadKnowledge
) -> None:
    path = knowledge_file(tmp_path / "told.json", paper_head(), knowledge)
    assert read_calibration(path, paper_head()).knowledge == knowledge


def test_a_file_for_one_head_is_refused_by_another(tmp_path: Path) -> None:
    path = knowledge_file(tmp_path / "told.json", paper_head(), HeadKnowledge())
    with pytest.raises(ValueError, match="made for a different head"):
        read_calibration(path, PRESETS["ideal"]())


def test_a_knowledge_with_its_own_belief_is_not_written(tmp_path: Path) -> None:
    from headsim.sim.settings import HeadBelief

    with pytest.raises(ValueError, match="no belief"):
        knowledge_file(tmp_path / "told.json", paper_head(), HeadKnowledge(belief=HeadBelief()))
    assert not (tmp_path / "told.json").exists()


MODEL2_DOC = {
    "description": "one target",
    "experiment": {"procedure": "model2"},
    "scene": {"targets": [{"position_head_m": [0.0, 0.0, 0.8]}]},
}


@pytest.mark.parametrize(
    "settings",
    [
        HeadSettings(cameras=(paper_head().cameras[0], paper_head().cameras[0])),
        HeadSettings(
            seed=4,
            cameras=(CameraSettings(cx=279.5, cy=199.5), CameraSettings().with_zoom(1.5)),
        ),
    ],
    ids=["paper camera 1 twice", "shifted and zoomed"],
)
def test_a_heads_cameras_are_stated_key_by_key(settings: HeadSettings) -> None:
    scenario = scenario_with_head(MODEL2_DOC, "cameras", settings)
    assert scenario.settings == settings
    assert scenario.seed == settings.seed


def test_a_head_the_tables_cannot_state_is_refused() -> None:
    with pytest.raises(ValueError, match=r"\[head\], \[cam1\] and \[cam2\] cannot state"):
        scenario_with_head(MODEL2_DOC, "backlash", HeadSettings(backlash_rad=0.0003))


def test_a_head_built_off_its_design_is_stated_as_its_preset() -> None:
    settings = PRESETS["realistic"](seed=3)
    assert HeadSettings(cameras=settings.cameras) != settings  # not the cameras alone
    scenario = scenario_with_head(MODEL2_DOC, "realistic", settings)
    assert scenario.settings == settings and scenario.seed == 3
