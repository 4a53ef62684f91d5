"""The eye servo and Model 2 over heads in lockstep (:class:`~headsim.lockstep.settled.SettledHeads`).

Every head runs the classic servo's law (:class:`headsim.active.eye_servo.EyeServo`: the
probe, secant gains, the pixel-locking stop, retreats at half the move) on its own
target; each round every head still servoing makes its move, then all of them settle in
one batch call, one camera of all of them is drawn through one context and the markers
are found over the stack (:func:`~headsim.lockstep.detect.find_markers_stacked`).  A
head stops when it converges (or fails); the round goes on with the rest.  Model 2
(:func:`headsim.active.model2.measure_model2`) runs its two steps, y images and
near-midline remedy the same way, and estimates every head's point in one call of the
pure estimator.  The classic path stays the reference (tests/lockstep compares them).

What lockstep does not do: scanning the eye range for a target camera 1 does not see
at the start, and searching for one camera 2 does not see where camera 1 fixates
(:mod:`headsim.active.search`).  Such a head ends ``needs_classic`` with the reason, for a
caller to measure on the classic path.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from headsim.active.failure import Failure, FailureCause, detection_failure, servo_failure
from headsim.active.look import expected_window, stands_for_frame, unbinned_px
from headsim.active.measurement import NOMINAL_PIXEL_SIGMA, HeadKnowledge
from headsim.active.model2 import Model2Config, _nearest_seen
from headsim.active.servo_types import ServoConfig, ServoOutcome, ServoResult
from headsim.estimators import Uncertainty, model2
from headsim.geometry.transforms import apply_transform
from headsim.sim.gl_window import Window
from headsim.vision.detection import Detection, DetectionStatus
from headsim.vision.markers import find_marker

from .detect import find_markers_stacked
from .settled import SettledHeads


@dataclass(frozen=True)
class LockstepTarget:
    """A marker a head measures: its name, colour, mocap body and true position (W, m)."""

    name: str
    colour: str
    body: str
    position_world_m: tuple[float, float, float]


@dataclass(frozen=True)
class HeadEstimate:
    """One head's Model 2 measurement: ``status`` "ok", "failed" or "needs_classic"
    (``detail`` says why); estimate and truth in H, m; images taken; servo residuals, px."""

    name: str
    status: str
    estimate_head_m: np.ndarray
    truth_head_m: np.ndarray
    renders: int
    residuals_px: tuple[float, ...]
    detail: str = ""
    failure: Failure | None = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def error_pct_of_depth(self) -> float:
        """|estimate - truth| as a percentage of the true depth (NaN unless ok)."""
        error = np.linalg.norm(self.estimate_head_m - self.truth_head_m)
        return float(100.0 * error / self.truth_head_m[2])


@dataclass(frozen=True)
class Expected:
    """Where a head expects its marker (full-frame px), its area (px) and the image
    motion since it was seen (px): what places a window (:func:`expected_window`)."""

    uv_px: tuple[float, float]
    area_px: float
    motion_px: float
    margin_px: float


def observe(
    heads: SettledHeads,
    ids: Sequence[int],
    camera: int,
    colours: Sequence[str],
    expected: Sequence[Expected | None] | None = None,
    previews: Sequence[int] | None = None,
    margins: Sequence[float] = (),
) -> tuple[list[Detection], list[int]]:
    """Camera ``camera``'s detection of each head's marker (``colours[row]``) now, and the
    images each took.  Where ``expected`` places a window, only it is drawn, and its
    detection kept if the full frame would give the same answer (:func:`stands_for_frame`,
    the classic looker's rule); a miss is looked for again in the full frame.  Where a
    row has no expectation and ``previews`` gives a binning b > 1, a binned preview
    places the window first (``margins``: each row's window margin, px)."""
    n = len(ids)
    if not n:
        return [], []
    size = heads.image_size_px
    windows: list[Window | None] = [
        None if e is None else expected_window(size, e.uv_px, e.area_px, e.motion_px, e.margin_px)
        for e in (expected or [None] * n)
    ]
    takes = [1] * n
    for row, b in enumerate(previews or [0] * n):
        if windows[row] is None and b > 1:  # the classic looker's preview, then its window
            takes[row] += 1
            seen = find_marker(heads.preview(ids[row], camera, b), colours[row])
            if seen.found and seen.uv is not None:
                u, v = unbinned_px(seen.uv, b)
                windows[row] = expected_window(
                    size, (float(u), float(v)), b * b * seen.area_px, 4.0 * b, margins[row]
                )
    images = heads.render(np.asarray(ids, np.int64), camera, windows)
    out: list[Detection | None] = [None] * n
    for row, window in enumerate(windows):
        if window is not None:
            seen = find_marker(images[row], colours[row])
            placed = None if expected is None else expected[row]
            area = None if placed is None else placed.area_px
            out[row] = stands_for_frame(seen, window, size, area)
    _detect_whole(images, colours, [r for r in range(n) if windows[r] is None], out)
    missed = [r for r in range(n) if out[r] is None]
    if missed:
        again = heads.render(np.asarray([ids[r] for r in missed], np.int64), camera)
        found: list[Detection | None] = [None] * len(missed)
        _detect_whole(again, [colours[r] for r in missed], list(range(len(missed))), found)
        for r, d in zip(missed, found, strict=True):
            out[r] = d
            takes[r] += 1
    return [d if d is not None else Detection(DetectionStatus.LOST, None, 0.0) for d in out], takes


def _detect_whole(
    images: Sequence[np.ndarray],
    colours: Sequence[str],
    rows: Sequence[int],
    out: list[Detection | None],
) -> None:
    """``out[row]``: the marker of ``colours[row]`` in whole frame ``images[row]``, found
    over the stack of each colour's frames."""
    groups: dict[str, list[int]] = {}
    for row in rows:
        groups.setdefault(colours[row], []).append(row)
    for colour, members in groups.items():
        stack = np.stack([images[row] for row in members])
        for row, found in zip(members, find_markers_stacked(stack, colour), strict=True):
            out[row] = found


@dataclass
class _Servo:
    """One head's servo: the classic ``EyeServo._servo``'s state between moves."""

    head: int
    colour: str
    cfg: ServoConfig
    goal: float
    steps: int
    uv: tuple[float, float]
    gain: float | None
    renders: int
    probe: int
    damping: float = 1.0
    iteration: int = 1
    retreats: int = 0
    visited: dict[int, tuple[float, float]] = field(default_factory=dict)
    path: list[tuple[int, float, float]] = field(default_factory=list)
    move: int = 0
    area: float = 0.0
    bound: float = 0.0
    result: ServoResult | None = None

    def finish(
        self,
        outcome: ServoOutcome,
        steps: int,
        uv: tuple[float, float] | None,
        iterations: int,
        lost: DetectionStatus | None = None,
    ) -> None:
        residual = math.nan if uv is None else uv[0] - self.goal
        gain = self.gain
        subpixel = float(steps) if gain is None or uv is None else steps - residual / gain
        self.result = ServoResult(
            outcome, steps, uv, residual, gain, subpixel, self.renders, iterations, lost,
            tuple(self.path), self.retreats,
        )  # fmt: skip


def servo_heads(
    heads: SettledHeads,
    ids: Sequence[int],
    camera: int,
    colours: Sequence[str],
    goals_u: Sequence[float],
    gains: Sequence[float | None],
    configs: Sequence[ServoConfig],
    first: Sequence[Detection] | None = None,
) -> list[ServoResult]:
    """Drive each head's eye until ``camera`` sees its marker at its goal column, all in
    lockstep; each head's result as :meth:`EyeServo.run`'s (no fixation averaging).
    ``gains``: each head's gain to start from (None: probe); ``first``: detections already
    made at the heads' eyes (saves a render); ``configs``: each head's servo settings."""
    low, high = heads.step_range
    steps0 = heads.eye_steps(ids)
    taken = [0] * len(ids)
    if first is None:
        first, taken = observe(heads, ids, camera, colours, None, *_previews(configs))
    states = []
    for row, head in enumerate(ids):
        cfg = configs[row]
        s = _Servo(
            int(head), colours[row], cfg, float(goals_u[row]), int(steps0[row]),
            (math.nan, math.nan), gains[row], taken[row], cfg.probe_steps,
        )  # fmt: skip
        s.bound = heads.gain_bound(int(head), camera)
        seen = first[row]
        if not seen.found or seen.uv is None:
            s.finish(ServoOutcome.TARGET_LOST, s.steps, None, 0, lost=seen.status)
        else:
            s.uv, s.area = seen.uv, seen.area_px
            s.visited[s.steps] = seen.uv
            s.path.append((s.steps, *seen.uv))
        states.append(s)
    active = [s for s in states if s.result is None]
    while active:
        moving, settle_only = _decide(active, (low, high))
        heads.command_eye_steps(
            np.array([s.head for s, _ in settle_only], np.int64),
            np.array([step for _, step in settle_only], np.int64),
        )
        targets = np.array([s.steps + s.move for s in moving], np.int64)
        heads.command_eye_steps(np.array([s.head for s in moving], np.int64), targets)
        found, takes = observe(
            heads,
            [s.head for s in moving],
            camera,
            [s.colour for s in moving],
            [_expected(s) for s in moving],
        )
        back = [
            s
            for s, target, d, take in zip(moving, targets, found, takes, strict=True)
            if _moved(s, int(target), d, take)
        ]
        heads.command_eye_steps(
            np.array([s.head for s in back], np.int64), np.array([s.steps for s in back], np.int64)
        )
        active = [s for s in active if s.result is None]
    return [s.result for s in states if s.result is not None]


def _decide(
    active: list[_Servo], limits: tuple[int, int]
) -> tuple[list[_Servo], list[tuple[_Servo, int]]]:
    """Each head's next move (the classic loop's head): the heads that move, and those that
    stop at a visited step they must go back to."""
    moving, settle_only = [], []
    for s in active:
        cfg, iteration, gain, uv, steps = s.cfg, s.iteration, s.gain, s.uv, s.steps
        error = uv[0] - s.goal
        if gain is not None and abs(error) <= max(cfg.tolerance_px, 0.5 * abs(gain)):
            s.finish(ServoOutcome.CONVERGED, steps, uv, iteration - 1)
            continue
        if gain is None:
            move = s.probe if steps + s.probe <= limits[1] else -s.probe
            move = round(move * s.damping) or (1 if move > 0 else -1)
        else:
            move = round(-s.damping * error / gain) or (-1 if error / gain > 0 else 1)
        target = steps + move
        if not limits[0] <= target <= limits[1]:
            s.finish(ServoOutcome.JOINT_LIMIT, steps, uv, iteration - 1)
            continue
        if target in s.visited:
            best = min(s.visited, key=lambda k: abs(s.visited[k][0] - s.goal))
            if best != steps:
                settle_only.append((s, best))
            s.finish(ServoOutcome.CONVERGED, best, s.visited[best], iteration)
            continue
        s.move = move
        moving.append(s)
    return moving, settle_only


def _previews(configs: Sequence[ServoConfig]) -> tuple[list[int], list[float]]:
    """Each head's preview binning (0: none, as without windows) and window margin."""
    return (
        [c.preview_binning if c.windows else 0 for c in configs],
        [c.window_margin_px for c in configs],
    )


def _expected(s: _Servo) -> Expected | None:
    """Where the head's next image should show its marker (the classic looker's window
    after a move): predicted by the gain, or before one is learnt, a window wide enough
    for ``bound`` px a step either way; None: the full frame."""
    if not s.cfg.windows or s.area <= 0:
        return None
    if s.gain is None:  # expected_window grows by a quarter of the motion
        return Expected(s.uv, s.area, 4.0 * s.bound * abs(s.move), s.cfg.window_margin_px)
    motion = s.gain * s.move
    return Expected((s.uv[0] + motion, s.uv[1]), s.area, motion, s.cfg.window_margin_px)


def _moved(s: _Servo, target: int, detection: Detection, take: int) -> bool:
    """Take in a move's image (the classic loop's body; ``take`` images drawn for it); True
    when the move is undone."""
    cfg = s.cfg
    s.renders += take
    iteration, move = s.iteration, s.move
    if not detection.found or detection.uv is None:
        if s.retreats >= cfg.max_retreats or abs(move) <= 1:
            s.finish(ServoOutcome.TARGET_LOST, target, None, iteration, lost=detection.status)
            return False
        s.retreats += 1
        s.damping *= 0.5
        s.iteration += 1
        _out_of_moves(s)
        return True
    change = detection.uv[0] - s.uv[0]
    if s.gain is None:
        if abs(change) >= cfg.min_probe_px:
            s.gain = change / move
        else:
            s.probe *= 4
    elif abs(move) >= cfg.min_secant_steps and change != 0.0:
        s.gain = change / move
    s.steps, s.uv, s.area = target, detection.uv, detection.area_px
    s.visited[target] = detection.uv
    s.path.append((target, *detection.uv))
    s.iteration += 1
    _out_of_moves(s)
    return False


def _out_of_moves(s: _Servo) -> None:
    """After the last move the classic loop allows: converged if within tolerance."""
    cfg = s.cfg
    if s.iteration <= cfg.max_iterations or s.result is not None:
        return
    done = s.gain is not None and abs(s.uv[0] - s.goal) <= max(cfg.tolerance_px, 0.5 * abs(s.gain))
    outcome = ServoOutcome.CONVERGED if done else ServoOutcome.ITERATION_LIMIT
    s.finish(outcome, s.steps, s.uv, cfg.max_iterations)


@dataclass(frozen=True)
class HeadJob:
    """What one head measures with: its target, what it knows, its Model 2 and servo
    settings."""

    target: LockstepTarget
    knowledge: HeadKnowledge
    model2: Model2Config
    servo: ServoConfig


def measure_model2_heads(heads: SettledHeads, jobs: Sequence[HeadJob]) -> list[HeadEstimate]:
    """Model 2 on ``jobs[i].target`` by head i, every head in lockstep (see the module)."""
    n = len(jobs)
    if n > heads.n:
        raise ValueError(f"{n} targets for {heads.n} heads: at most one target a head")
    refs = [
        (
            j.knowledge.reference_of(heads.settings[h], 1),
            j.knowledge.reference_of(heads.settings[h], 2),
        )
        for h, j in enumerate(jobs)
    ]
    colours = [j.target.colour for j in jobs]
    servos = [j.servo for j in jobs]
    ids = list(range(n))
    renders = np.zeros(n, np.int64)
    ends: dict[int, tuple[str, Failure | str | None, tuple[float, ...]]] = {}

    def end(
        head: int, status: str, why: Failure | str | None, residuals: tuple[float, ...]
    ) -> None:
        ends[head] = (status, why, residuals)

    def pick(rows: list[int]) -> tuple[list[str], list[ServoConfig]]:
        return [colours[h] for h in rows], [servos[h] for h in rows]

    goals1 = [refs[h][0][0] for h in ids]
    step1 = servo_heads(heads, ids, 1, colours, goals1, [None] * n, servos)
    for head, r in zip(ids, step1, strict=True):
        renders[head] += r.renders
        if r.outcome is ServoOutcome.TARGET_LOST and r.iterations == 0:
            end(head, NEEDS_CLASSIC, "camera 1 does not see it at the start: a scan", ())
        elif not r.converged:
            end(head, "failed", servo_failure(r, "step 1", 1), (r.residual_px,))
    go = [h for h in ids if h not in ends]
    seen2, takes = observe(heads, go, 2, pick(go)[0], None, *_previews(pick(go)[1]))
    renders[go] += takes
    for head, d in zip(go, seen2, strict=True):
        if not d.found or d.uv is None:
            reason = "camera 2 does not see it where camera 1 fixates: a search"
            end(head, NEEDS_CLASSIC, reason, ())
    first2 = dict(zip(go, seen2, strict=True))
    go = [h for h in go if h not in ends]
    step2 = dict(
        zip(
            go,
            servo_heads(
                heads,
                go,
                2,
                pick(go)[0],
                [refs[h][1][0] for h in go],
                [None] * len(go),
                pick(go)[1],
                first=[first2[h] for h in go],
            ),
            strict=True,
        )
    )
    for head, r in step2.items():
        renders[head] += r.renders
        if not r.converged:
            residuals = (step1[head].residual_px, r.residual_px)
            end(head, "failed", servo_failure(r, "step 2", 2), residuals)
    go = [h for h in go if h not in ends]
    # Camera 1 last saw it where step 1 ended: its window follows step 2's move.
    seen1, takes = observe(
        heads,
        go,
        1,
        pick(go)[0],
        [_after_step2(step1[h], step2[h], first2[h].area_px, servos[h]) for h in go],
    )
    renders[go] += takes
    images = _Images(
        {}, {h: np.array(first2[h].uv) for h in go}, {}, {h: step1[h].steps for h in go}
    )
    for head, d in zip(go, seen1, strict=True):
        if d.found and d.uv is not None:
            images.uv1[head], images.gamma1[head] = np.array(d.uv), step2[head].steps
            continue
        memory = _nearest_seen(
            step1[head].seen, step2[head].steps, refs[head][0][0], jobs[head].model2.midline_px
        )
        if memory is None:
            residuals = (step1[head].residual_px, step2[head].residual_px)
            end(head, "failed", detection_failure(d, "step 2", 1), residuals)
        else:
            images.uv1[head], images.gamma1[head] = np.array(memory[1:]), memory[0]
    go = [h for h in go if h not in ends]
    _remedy(heads, go, colours, step1, step2, refs, jobs, images, renders)
    estimates = _estimate(heads, go, jobs, refs, step1, step2, images)
    for head in go:
        residuals = (step1[head].residual_px, step2[head].residual_px)
        found = estimates[head]
        if isinstance(found, str):
            end(head, "failed", Failure(FailureCause.ESTIMATOR, "estimate", None, found), residuals)
        else:
            end(head, "ok", None, residuals)
    out = []
    for head, job in enumerate(jobs):
        status, why, spent = ends[head]
        truth = apply_transform(heads.head_from_world(head), np.array(job.target.position_world_m))
        estimate = estimates.get(head)
        out.append(
            HeadEstimate(
                job.target.name,
                status,
                estimate if isinstance(estimate, np.ndarray) else np.full(3, np.nan),
                np.asarray(truth).reshape(3),
                int(renders[head]),
                spent,
                why.message if isinstance(why, Failure) else why or "",
                why if isinstance(why, Failure) else None,
            )
        )
    return out


def _after_step2(
    step1: ServoResult, step2: ServoResult, area_px: float, cfg: ServoConfig
) -> Expected | None:
    """Where camera 1 should see the marker after step 2: step 1's last sight moved by its
    gain over step 2's move (``area_px``: camera 2's sight, a like size)."""
    if step1.uv is None or step1.gain_px_per_step is None or not cfg.windows:
        return None
    motion = step1.gain_px_per_step * (step2.steps - step1.steps)
    u, v = step1.uv
    return Expected((u + motion, v), area_px, motion, cfg.window_margin_px)


#: A head's status when lockstep stops short of what the classic path would do next.
NEEDS_CLASSIC = "needs_classic"


@dataclass
class _Images:
    """Each head's y images (px) and the eye steps they were taken at."""

    uv1: dict[int, np.ndarray]
    uv2: dict[int, np.ndarray]
    gamma1: dict[int, int]
    gamma2: dict[int, int]


#: What the estimator is told, shared by the heads estimated in one call.
_Key = tuple[
    float,
    tuple[tuple[float, float], tuple[float, float]],
    tuple[float, float],
    tuple[float, float],
    tuple[float, float],
    float,
    bool,
    float,
]


def _estimate(
    heads: SettledHeads,
    go: list[int],
    jobs: Sequence[HeadJob],
    refs: Sequence[tuple[tuple[float, float], tuple[float, float]]],
    step1: Sequence[ServoResult],
    step2: dict[int, ServoResult],
    images: _Images,
) -> dict[int, np.ndarray | str]:
    """Each head's point in H (or why the estimator refused it): one call of the pure
    estimator for all the heads that share what it is told (``measure_model2``'s inputs)."""
    groups: dict[_Key, list[int]] = {}
    for h in go:
        knowledge, config = jobs[h].knowledge, jobs[h].model2
        resolution = float(heads.resolution_rad[h])
        gain = min(abs(r.gain_px_per_step or 1.0) for r in (step1[h], step2[h]))
        sigma = (
            resolution * NOMINAL_PIXEL_SIGMA / gain
            if config.interpolate
            else resolution / math.sqrt(12.0)
        )
        settings = heads.settings[h]
        key: _Key = (
            knowledge.head_belief_of(settings).baseline_m,
            refs[h],
            knowledge.alpha_e,
            knowledge.kx_over_ky,
            knowledge.line_of_sight_offsets_of(settings),
            sigma,
            config.interpolate,
            resolution,
        )
        groups.setdefault(key, []).append(h)
    out: dict[int, np.ndarray | str] = {}
    for key, rows in groups.items():
        baseline, ref, alpha_e, kx_over_ky, los, sigma, interpolate, resolution = key

        def angle(r: ServoResult, interpolate: bool = interpolate) -> float:
            return (r.subpixel_steps if interpolate else float(r.steps)) * resolution  # noqa: B023

        estimate = model2(
            [angle(step1[h]) for h in rows],
            [angle(step2[h]) for h in rows],
            np.array([images.uv1[h] for h in rows]),
            np.array([images.uv2[h] for h in rows]),
            baseline,
            uv10=ref[0],
            uv20=ref[1],
            alpha_e=alpha_e,
            gamma1=[images.gamma1[h] * resolution for h in rows],
            gamma2=[images.gamma2[h] * resolution for h in rows],
            kx_over_ky=kx_over_ky,
            uncertainty=Uncertainty(encoder=sigma, pixel=NOMINAL_PIXEL_SIGMA),
            los_offset_m=los,
        )
        for row, h in enumerate(rows):
            valid = bool(estimate.valid[row])
            out[h] = estimate.positions[row] if valid else repr(estimate.reasons(row))
    return out


def _remedy(
    heads: SettledHeads,
    go: list[int],
    colours: Sequence[str],
    step1: Sequence[ServoResult],
    step2: dict[int, ServoResult],
    refs: Sequence[tuple[tuple[float, float], tuple[float, float]]],
    jobs: Sequence[HeadJob],
    images: _Images,
    renders: np.ndarray,
) -> None:
    """The near-midline remedy (``measure_model2``'s) for the heads that need it: both
    cameras' images at an eye angle ``remedy_px`` of image motion off the fixations,
    taken in place of a y image that lies farther from its goal column."""
    low, high = heads.step_range
    need, poses = [], []
    for h in go:
        (u10, _), (u20, _) = refs[h]
        config = jobs[h].model2
        if min(abs(images.uv1[h][0] - u10), abs(images.uv2[h][0] - u20)) >= config.midline_px:
            continue
        gain = max(abs(step1[h].gain_px_per_step or 0.0), abs(step2[h].gain_px_per_step or 0.0))
        if gain == 0.0:
            continue
        offset = round(config.remedy_px / gain)
        middle = (step1[h].steps + step2[h].steps) / 2
        pose = round(middle - offset) if middle - offset >= low else round(middle + offset)
        if low <= pose <= high:
            need.append(h)
            poses.append(pose)
    if not need:
        return
    heads.command_eye_steps(np.array(need, np.int64), np.array(poses, np.int64))
    seen = []
    for camera in (1, 2):
        found, takes = observe(heads, need, camera, [colours[h] for h in need])
        seen.append(found)
        renders[need] += takes
    for row, (h, pose) in enumerate(zip(need, poses, strict=True)):
        (u10, _), (u20, _) = refs[h]
        r1, r2 = (s[row].uv if s[row].found else None for s in seen)
        if r1 is not None and abs(r1[0] - u10) > abs(images.uv1[h][0] - u10):
            images.uv1[h], images.gamma1[h] = np.array(r1), pose
        if r2 is not None and abs(r2[0] - u20) > abs(images.uv2[h][0] - u20):
            images.uv2[h], images.gamma2[h] = np.array(r2), pose


__all__ = [
    "NEEDS_CLASSIC",
    "Expected",
    "HeadEstimate",
    "HeadJob",
    "LockstepTarget",
    "measure_model2_heads",
    "observe",
    "servo_heads",
]
