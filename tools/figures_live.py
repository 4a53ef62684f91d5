"""The documentation's figures of whole studies and the head in time: reproduce, live gaze, Gymnasium."""

from __future__ import annotations

import json
import math
import tempfile
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
from figures_common import benchmark, span

# --- headsim reproduce --------------------------------------------------------------


def _reproduce_rows(fast: bool = False) -> list[dict[str, str]]:
    """Every row of ``headsim reproduce``'s report (seed 0, two workers), in order."""
    from headsim.studies.reproduce import reproduce as run

    with tempfile.TemporaryDirectory(prefix="readme-figures-") as out:
        state = run(out, fast=fast, workers=2)
        if state["status"] != "ok":
            raise RuntimeError(f"headsim reproduce: {state['status']}")
        report = json.loads((Path(out) / "report.json").read_text())
    return [row for rows in report["rows"].values() for row in rows]


def reproduce() -> str:
    """The report's verdicts at full size: how many rows are reproduced, and which are not."""
    rows = _reproduce_rows()
    tally = Counter(
        "reproduced"
        if r["verdict"].startswith("reproduced")
        else "not"
        if r["verdict"].startswith(("not reproduced", "FAILED"))
        else "other"
        for r in rows
    )
    missed = "; ".join(
        f"{r['quantity']}: {r['ours']}" for r in rows if r["verdict"].startswith(("not", "FAILED"))
    )
    stereo = next(r for r in rows if r["quantity"].startswith("stereo"))
    return (
        f"`headsim reproduce` (full size, seed 0): {tally['reproduced']} of the report's "
        f"{len(rows)} rows reproduced, {tally['not']} not reproduced or failed, "
        f"{tally['other']} without a paper figure to compare (calibrated stereo's RMS 3-D error, "
        f"the reference of Tables V/VI: {stereo['ours']} mm). Not reproduced: {missed}.\n"
    )


def speed() -> str:
    """Wall times as ratios to a 640x480 render timed in the same process: the quick start
    and ``headsim reproduce --fast`` (its report's own ratio)."""
    import time

    from headsim.runs.runner import run_scenario
    from headsim.scenario.loading import load_scenario
    from headsim.studies.render_clock import CLOCK_RENDERS, RenderClock
    from headsim.studies.reproduce import reproduce as run

    render_s = RenderClock().sample(CLOCK_RENDERS[0])
    start = time.perf_counter()
    run_scenario(load_scenario("quickstart"))
    quickstart_s = time.perf_counter() - start
    with tempfile.TemporaryDirectory(prefix="readme-figures-") as out:
        state = run(out, fast=True, workers=2)
        if state["status"] != "ok":
            raise RuntimeError(f"headsim reproduce --fast: {state['status']}")
        report = json.loads((Path(out) / "report.json").read_text())
    return (
        f"`headsim run quickstart` took {quickstart_s / render_s:.0f} renders' time (the wall "
        f"time over one 640x480 render of the ideal head, timed in the same process); "
        f"`headsim reproduce --fast --workers 2` {report['wall_over_render']:.0f} (its report's "
        f"`wall_over_render`).\n"
    )


# --- the live head ------------------------------------------------------------------

#: ``live_gaze.py --fast``'s size: one depth, 1 s of pursuit, three jump sizes.
LIVE_DEPTH_M, LIVE_SECONDS, JUMPS_DEG = 1.0, 1.0, (10, 20, 30)


def _range(figs: list[dict[str, float]], key: str, digits: int) -> str:
    return span((f[key] for f in figs), digits)


def _neck_move_ms(degrees: float, profile: Any) -> float:
    """The neck's move for a jump of ``degrees`` at the motors' limits (no run: the profiles)."""
    from headsim.live.gaze import SaccadeProfile
    from headsim.live.head import NECK_LIMITS
    from headsim.live.motors import bang_bang_duration, min_jerk_duration

    fn = min_jerk_duration if profile is SaccadeProfile.MIN_JERK else bang_bang_duration
    direction, angle = math.radians(35.0), math.radians(degrees)
    moves = (angle * math.cos(direction), angle * math.sin(direction))  # yaw, pitch
    return 1000 * max(fn(m, NECK_LIMITS) for m in moves)


def live_gaze() -> str:
    """Pursuit with and without the predictor, saccades, the eyes alone (``--fast``'s size)."""
    from headsim.live.gaze import GazeMode, SaccadeProfile

    lg = benchmark("live_gaze")
    ideal = lg.make_head("ideal")
    paths = lg.paths(LIVE_DEPTH_M, 0.3, LIVE_SECONDS, seed=int(LIVE_DEPTH_M * 10))
    runs = {
        (name, predictor): lg.pursuit_case(path, predictor, LIVE_SECONDS, ideal)
        for name, path in paths.items()
        for predictor in (True, False)
    }
    on = [f for (_, p), f in runs.items() if p]
    off = [f for (_, p), f in runs.items() if not p]
    losses = sum(f.get("losses", math.nan) for f in runs.values())
    lags = ", ".join(f"{name} {runs[name, True]['lag_ms']:.0f}" for name in paths)
    saccades = []
    for degrees in JUMPS_DEG:
        times = [lg.saccade_case(degrees, p, ideal)["time_to_fixation_ms"] for p in SaccadeProfile]
        neck = [_neck_move_ms(degrees, p) for p in SaccadeProfile]
        saccades.append(
            f"{degrees} deg {' / '.join(f'{t:.0f}' for t in times)} ms (the neck's move at its "
            f"limits {' / '.join(f'{t:.0f}' for t in neck)})"
        )
    sinusoid = paths["sinusoid"]
    eyes = [lg.pursuit_case(sinusoid, p, LIVE_SECONDS, ideal, GazeMode.EYES) for p in (True, False)]
    # The realistic head, calibrated as the bench calibrates it, measuring with its belief.
    realistic = lg.make_head("realistic")
    real = [lg.pursuit_case(path, True, LIVE_SECONDS, realistic) for path in paths.values()]
    real_rms = ", ".join(
        f"{name} {f['rms_pct_of_depth']:.3f}" if f.get("acquired") else f"{name} not acquired"
        for name, f in zip(paths, real, strict=True)
    )
    return (
        f"`benchmarks/live_gaze.py --fast` (640 x 480 ideal cameras, 30 Hz, 1 frame latency, "
        f"Model 1 with the neck, {LIVE_SECONDS:g} s at up to 0.3 m/s at {LIVE_DEPTH_M:g} m: "
        f"lateral waypoints, a sinusoid and a random walk): {losses:.0f} losses in the "
        f"{len(runs)} runs. Position error RMS along the path, with the predictor: "
        f"{_range(on, 'rms_pct_of_depth', 3)} % of distance ({_range(on, 'rms_mm', 1)} mm); "
        f"without it: {_range(off, 'rms_pct_of_depth', 3)} % ({_range(off, 'rms_mm', 1)} mm). "
        f"Pursuit lag with the predictor: {lags} ms; without it {_range(off, 'lag_ms', 0)} ms. "
        "Saccades at 1 m (jumps 35 degrees above the horizontal), time from the jump to the "
        f"first frame within 1 px of the goals, minimum-jerk / bang-bang: {'; '.join(saccades)}. "
        f'With the eyes alone (`mode = "eyes"`, the neck still; the sinusoid): '
        f"{sum(f['losses'] for f in eyes):.0f} losses, position RMS "
        f"{eyes[0]['rms_pct_of_depth']:.3f} % of distance with image offsets of "
        f"{eyes[0]['offset_rms_px']:.0f} px RMS (one eye motor cannot put a target off the "
        "midline on both goal columns); without the predictor "
        f"{eyes[1]['rms_pct_of_depth']:.3f} %. The realistic preset (after the extended "
        "calibration on 30 balls and a 1 mm tape; it measures with what it believes of its "
        f"geometry), with the predictor: position RMS {real_rms} % of distance.\n"
    )


# --- the Gymnasium environment ------------------------------------------------------

#: ``gym_env.py``'s episodes: the paper-servo policy's and the random policy's.
SERVO_EPISODES, RANDOM_EPISODES = 100, 20


#: The realistic budget's geometry errors: the true head, and what it believes of itself.
TRUE_GEOMETRY_M = {"baseline_m": 0.1503, "neck_d1_m": 0.1205, "neck_a2_m": 0.0895}
BELIEVED_GEOMETRY_M = {"baseline_m": 0.150, "neck_d1_m": 0.120, "neck_a2_m": 0.090}


def pursuit_belief() -> str:
    """``headsim run pursuit`` (1.5 s) on a head built off its design: measured with its
    belief, and with a belief that happens to be the truth (what a leak of truth gave)."""
    from headsim.runs.runner import run_scenario
    from headsim.scenario.loading import load_scenario

    def rms(belief: dict[str, float]) -> Any:
        overrides: dict[str, Any] = {"scene.pursuit.duration_s": 1.5}
        overrides |= {f"head.{k}": v for k, v in TRUE_GEOMETRY_M.items()}
        overrides |= {f"belief.{k}": v for k, v in belief.items()}
        experiment = run_scenario(load_scenario("pursuit", overrides=overrides)).experiment
        return experiment.figures  # type: ignore[union-attr]

    built, known = rms(BELIEVED_GEOMETRY_M), rms(TRUE_GEOMETRY_M)
    return (
        "`headsim run pursuit` for 1.5 s on a head built off its design (true D 150.3 mm, "
        "d1 120.5 mm, a2 89.5 mm) that believes the design (150 / 120 / 90 mm): position "
        f"RMS **{built.position_rms_pct_of_depth:.3f} % of distance** "
        f"({1e3 * built.position_rms_m:.2f} mm, {built.frames} frames, {built.frames_lost} "
        f"lost); a head whose belief were its true geometry would get "
        f"{known.position_rms_pct_of_depth:.3f} % ({1e3 * known.position_rms_m:.2f} mm).\n"
    )


def gym_policies() -> str:
    """The reference policies on seeded episodes of headsim/Fixate-v0."""
    import gymnasium

    import headsim.envs
    from headsim.envs.fixate import FixateEnv
    from headsim.envs.policies import RandomPolicy, ServoPolicy, VergencePolicy

    ge = benchmark("gym_env")
    env = gymnasium.make(headsim.envs.FIXATE_ID)
    try:
        servo = ge.episodes(
            env, ServoPolicy(env.action_space, env.unwrapped.period_s), SERVO_EPISODES
        )
        random = ge.episodes(env, RandomPolicy(env.action_space, seed=0), RANDOM_EPISODES)
    finally:
        env.close()
    plane = FixateEnv(scene="textured_plane")
    try:
        verging = ge.episodes(plane, VergencePolicy(plane.action_space, plane.period_s), 100)
    finally:
        plane.close()
    done = [n for n in servo if n is not None]
    verged = [n for n in verging if n is not None]
    return (
        f"The paper-servo policy fixated within 10 steps in {len(done)} of {len(servo)} seeded "
        f"episodes (mean {np.mean(done):.1f} steps, the first episode's probe steps included); "
        f"the random policy in {sum(n is not None for n in random)} of {len(random)}. On the "
        f'textured plane (`scene="textured_plane"`, pink noise at 0.3-2 m), the image-only '
        f"`VergencePolicy` verged within 1 px in {len(verged)} of {len(verging)} seeded "
        f"episodes (mean {np.mean(verged):.1f} steps).\n"
    )
