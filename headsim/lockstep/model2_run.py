"""A scenario's Model 2 targets measured by lockstep heads, one head a target.

Head k's scene holds the scenario's targets 1..k where the classic run has placed them
when it measures target k (:func:`headsim.procedures.each_target.measure_each_target`),
so each head sees what the classic head sees.  Every head starts at home with no gain
learnt, as the classic servo does on the first target (it carries its gains and eye pose
from one target to the next).
"""

from __future__ import annotations

import numpy as np

from headsim.active.measurement import HeadKnowledge
from headsim.runs.context import model2_config, servo_config
from headsim.scenario.spec import MARKER_BODIES, Scenario

from .servo import HeadEstimate, HeadJob, LockstepTarget, measure_model2_heads
from .settled import SettledHeads


def scenario_targets(scenario: Scenario) -> list[LockstepTarget]:
    """The scenario's marker targets, in the order the classic run measures them."""
    return [
        LockstepTarget(p.name, MARKER_BODIES[p.body], p.body, p.position_world_m)
        for p in scenario.scene.targets
    ]


def run_model2_lockstep(scenario: Scenario, knowledge: HeadKnowledge) -> list[HeadEstimate]:
    """Model 2 on each of ``scenario``'s targets, all in lockstep (see the module)."""
    if scenario.experiment.procedure != "model2" or scenario.scene.surface_targets is not None:
        raise ValueError(
            f"procedure {scenario.experiment.procedure!r}: lockstep runs Model 2 on marker "
            "targets; allowed: procedure = 'model2' without surface targets"
        )
    if scenario.settle_mode != "kinematic" or scenario.scene.room is not None:
        raise ValueError(
            "lockstep heads settle kinematically in the default scene; allowed: "
            "settle_mode = 'kinematic', no room"
        )
    model2, servo = model2_config(scenario), servo_config(scenario)
    jobs = [HeadJob(t, knowledge, model2, servo) for t in scenario_targets(scenario)]
    with SettledHeads([scenario.settings] * len(jobs)) as heads:
        for head in range(len(jobs)):
            for placed in scenario.scene.targets[: head + 1]:
                heads.place(head, placed.body, np.array(placed.position_world_m))
        return measure_model2_heads(heads, jobs)


__all__ = ["run_model2_lockstep", "scenario_targets"]
