"""What every phase builds from the scenario: parking, what the head is told, servo settings."""

from __future__ import annotations

from dataclasses import asdict

from headsim.active.measurement import HeadKnowledge
from headsim.paper import INITIAL_DIRECTIONS_RAD as PAPER_INITIAL_DIRECTIONS
from headsim.runs.context import PAPER, PARKED_WORLD_M, model2_config, servo_config, told
from headsim.scenario.loading import load_scenario


def test_unused_bodies_park_under_the_table() -> None:
    assert PARKED_WORLD_M[2] < 0.0


def test_the_head_is_told_only_the_goal_columns_the_scenario_gives() -> None:
    plain = load_scenario("chessboard", fast=True)
    assert plain.experiment.goal_columns_px is None and told(plain) == HeadKnowledge()
    goals = load_scenario(
        "chessboard", fast=True, overrides={"experiment.goal_columns_px": [300.0, 340.0]}
    )
    assert told(goals) == HeadKnowledge(u0=(300.0, 340.0))


def test_servo_and_model2_settings_are_the_scenarios() -> None:
    scenario = load_scenario("quickstart", fast=True)
    config_fields = asdict(servo_config(scenario))
    given = asdict(scenario.experiment.servo)
    assert given and all(config_fields[k] == v for k, v in given.items())
    config = model2_config(scenario)
    e = scenario.experiment
    assert (config.interpolate, config.midline_px, config.remedy_px) == (
        e.interpolate,
        e.midline_px,
        e.remedy_px,
    )
    assert tuple(PAPER["alpha_e_rad"]) == tuple(PAPER_INITIAL_DIRECTIONS)
