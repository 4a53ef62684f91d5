"""Uncalibrated visual servoing of the eye motor from images alone: no focal
length, no principal point.

The eye servo drives the eye motor, in whole encoder steps, until the chosen
camera sees the target at a goal column (the image centre).  Its gain (px per
encoder step) is measured from the images: a probe move when nothing is known,
then secant (1-D Broyden) updates after every large enough move.  A gain
learnt on one target seeds the next.  Every loop is bounded and returns a
:class:`headsim.active.servo_types.ServoResult` that says why it ended.

Averaging a converged fixation (``ServoConfig.average_fixation``): a blob's detected
column carries a sub-pixel rendering floor that depends on the pixel's phase and not
on the frame: repeated images at one pose repeat it.  One image's crossing (the
fractional encoder step where the column would meet its goal, from the learnt gain)
is therefore off by that floor over the gain, in encoder steps, which is more angle at
a shorter focal length.  Images at the whole steps that spread the target over one
pixel of image motion (the floor's period, :func:`pixel_period_steps`) sample every
phase; the mean of their crossings averages the floor out, at every zoom alike.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from headsim.active.events import ServoKind, ServoStep
from headsim.active.look import Looker, Since, finds_blob
from headsim.active.servo_types import (
    Detector,
    ServoConfig,
    ServoOutcome,
    ServoResult,
)
from headsim.head.servo_head import ServoHead
from headsim.sim.events import EventSink
from headsim.vision.detection import Detection, DetectionStatus


class EyeServo:
    """Servo the eye motor so that one camera's target column reaches a goal u."""

    def __init__(
        self, sim: ServoHead, config: ServoConfig | None = None, sink: EventSink | None = None
    ) -> None:
        self.sim = sim
        self.config = config or ServoConfig()
        #: Where detections and moves are reported (None: the simulator's sink).
        self.sink = sim.sink if sink is None else sink
        low, high = sim.joint_range("eye")
        resolution = sim.settings.encoder_resolution_rad
        self._step_range = (math.ceil(low / resolution), math.floor(high / resolution))
        #: Gain per camera, px per encoder step, carried from one target to the next.
        self.gains: dict[int, float] = {}
        #: Where the servo looks (windows, previews and what is kept between looks).
        self.looker = Looker(sim, self.config, self.sink)

    @property
    def step_range(self) -> tuple[int, int]:
        """Eye-motor range, whole encoder steps."""
        return self._step_range

    def observe(
        self, camera: int, detector: Detector, key: object = None, preview: bool = True
    ) -> Detection:
        """``camera``'s detection of ``detector``'s target now, through the servo's
        :class:`~headsim.active.look.Looker`: a window where the last sight and the gain
        put it, else a preview's window, else the full frame (``preview=False``: no
        preview, a search's look).  ``key``: what names the target (default the detector)."""
        return self.looker.look(camera, detector, Since(self.gains.get(camera), preview, key))

    def run(
        self,
        camera: int,
        detector: Detector,
        goal_u: float | None = None,
        first: Detection | None = None,
    ) -> ServoResult:
        """Drive the eye motor until ``camera`` sees the target at ``goal_u`` (image centre).

        ``first``: a detection already made at the current eye position (saves
        a render).  A move after which the target is gone is undone (back to
        the last step that saw it, no render needed) and retried at half the
        length, at most ``max_retreats`` times.  Once converged, the sub-step
        fixation may be averaged over images around the crossing (see
        ``ServoConfig.average_fixation``).
        """
        goal = self.sim.camera_settings(camera).image_centre[0] if goal_u is None else goal_u
        result = self._servo(camera, detector, goal, first)
        if result.converged:
            result = self._averaged(camera, detector, goal, result)
        return result

    def _averaged(
        self, camera: int, detector: Detector, goal: float, result: ServoResult
    ) -> ServoResult:
        """The converged ``result`` with its crossing averaged over images spread
        across one pixel around it (see ``ServoConfig.average_fixation``); the eye ends at
        ``result.steps``."""
        cfg, sim = self.config, self.sim
        gain = result.gain_px_per_step
        if not cfg.average_fixation or not gain or result.uv is None or not finds_blob(detector):
            return result
        low, high = self.step_range
        poses = [
            s
            for s in pixel_period_steps(result.subpixel_steps, gain, cfg.max_fixation_samples)
            if low <= s <= high
        ]
        seen = {s: u for s, u, _ in result.seen}
        path = list(result.seen)
        samples: list[tuple[int, float]] = []
        renders = 0
        for s in poses:  # bounded: at most max_fixation_samples poses
            if s not in seen:
                sim.command_eye_steps(s)
                sim.settle()
                detection = self.observe(camera, detector)
                renders += 1
                if not detection.found or detection.uv is None:
                    break  # the averaging is bounded by what the images show
                seen[s] = detection.uv[0]
                path.append((s, *detection.uv))
            samples.append((s, seen[s]))
        if sim.eye_encoder_steps() != result.steps:
            sim.command_eye_steps(result.steps)
            sim.settle()
        if len(samples) < 2:
            return replace(result, renders=result.renders + renders, seen=tuple(path))
        crossings = np.array([s - (u - goal) / gain for s, u in samples])
        subpixel = float(crossings.mean())
        return replace(
            result,
            subpixel_steps=subpixel,
            renders=result.renders + renders,
            seen=tuple(path),
            fixation_samples=len(samples),
        )

    def _servo(
        self, camera: int, detector: Detector, goal: float, first: Detection | None
    ) -> ServoResult:
        """The servo proper: whole-step moves until u is within tolerance of ``goal``."""
        sim, cfg = self.sim, self.config
        self._renders = 0
        steps = sim.eye_encoder_steps()
        if first is None:
            first = self.observe(camera, detector)
            self._renders += 1
        self._path: list[tuple[int, float, float]] = []
        self._retreats = 0
        if not first.found or first.uv is None:
            return self._result(
                ServoOutcome.TARGET_LOST, steps, None, goal, 0, camera, lost=first.status
            )
        visited: dict[int, tuple[float, float]] = {steps: first.uv}
        self._path.append((steps, *first.uv))
        uv = first.uv
        gain = self.gains.get(camera)
        probe = cfg.probe_steps
        damping = 1.0
        for iteration in range(1, cfg.max_iterations + 1):
            error = uv[0] - goal
            if gain is not None and abs(error) <= max(cfg.tolerance_px, 0.5 * abs(gain)):
                return self._result(
                    ServoOutcome.CONVERGED, steps, uv, goal, iteration - 1, camera, gain
                )
            if gain is None:
                move = probe if steps + probe <= self._step_range[1] else -probe
                move = round(move * damping) or (1 if move > 0 else -1)
            else:
                move = round(-damping * error / gain) or (-1 if error / gain > 0 else 1)
            target = steps + move
            if not self._step_range[0] <= target <= self._step_range[1]:
                return self._result(
                    ServoOutcome.JOINT_LIMIT, steps, uv, goal, iteration - 1, camera, gain
                )
            if target in visited:
                # Revisiting a step (pixel locking between neighbours): the best
                # visited step is as close as whole steps get.
                best = min(visited, key=lambda s: abs(visited[s][0] - goal))
                if best != steps:
                    sim.command_eye_steps(best)
                    sim.settle()
                return self._result(
                    ServoOutcome.CONVERGED, best, visited[best], goal, iteration, camera, gain
                )
            sim.command_eye_steps(target)
            sim.settle()
            detection = self.observe(camera, detector)
            self._renders += 1
            self.sink.emit(
                ServoStep(
                    ServoKind.EYE,
                    iteration,
                    (target,),
                    None
                    if not detection.found or detection.uv is None
                    else (detection.uv[0] - goal,),
                )
            )
            if not detection.found or detection.uv is None:
                if self._retreats >= cfg.max_retreats or abs(move) <= 1:
                    return self._result(
                        ServoOutcome.TARGET_LOST, target, None, goal, iteration, camera, gain,
                        lost=detection.status,
                    )  # fmt: skip
                # Re-acquire: back to the last step that saw it, then a shorter move.
                self._retreats += 1
                damping *= 0.5
                sim.command_eye_steps(steps)
                sim.settle()
                continue
            change = detection.uv[0] - uv[0]
            if gain is None:
                if abs(change) >= cfg.min_probe_px:
                    gain = change / move
                else:
                    probe *= 4
            elif abs(move) >= cfg.min_secant_steps and change != 0.0:
                gain = change / move
            if gain is not None:
                self.gains[camera] = gain  # what the next window is predicted with
            steps, uv = target, detection.uv
            visited[steps] = uv
            self._path.append((steps, *uv))
        # The last move may have landed within tolerance: that is converged.
        done = gain is not None and abs(uv[0] - goal) <= max(cfg.tolerance_px, 0.5 * abs(gain))
        outcome = ServoOutcome.CONVERGED if done else ServoOutcome.ITERATION_LIMIT
        return self._result(outcome, steps, uv, goal, cfg.max_iterations, camera, gain)

    def _result(
        self,
        outcome: ServoOutcome,
        steps: int,
        uv: tuple[float, float] | None,
        goal: float,
        iterations: int,
        camera: int,
        gain: float | None = None,
        lost: DetectionStatus | None = None,
    ) -> ServoResult:
        if gain is not None:
            self.gains[camera] = gain
        residual = math.nan if uv is None else uv[0] - goal
        subpixel = float(steps) if gain is None or uv is None else steps - residual / gain
        path = tuple(self._path)
        return ServoResult(
            outcome, steps, uv, residual, gain, subpixel, self._renders, iterations, lost, path,
            self._retreats,
        )  # fmt: skip


def pixel_period_steps(centre_steps: float, gain_px_per_step: float, most: int) -> list[int]:
    """Whole steps whose images spread evenly over one pixel of image motion around
    ``centre_steps``: consecutive steps, round(1 / |gain|) of them (one pixel's worth),
    every k-th step where that is more than ``most`` (at most ``most`` of them)."""
    per_pixel = max(1, round(1.0 / abs(gain_px_per_step)))
    stride = math.ceil(per_pixel / most)
    count = max(2, round(1.0 / (stride * abs(gain_px_per_step))))
    first = round(centre_steps - stride * (count - 1) / 2)
    return [first + stride * k for k in range(count)]


__all__ = ["EyeServo", "pixel_period_steps"]
