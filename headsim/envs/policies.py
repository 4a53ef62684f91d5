"""Reference policies for ``headsim/Fixate-v0``: the paper's servo as a policy, a vergence
policy for the textured plane, and a random one.

All see only what an agent sees: the observation (images, encoders) and the
action space (normalised, or in rad/s: ``FixateEnv``'s ``action_space`` option).  :class:`ServoPolicy` is the paper's uncalibrated servo
(``headsim.active.neck_servo.NeckServo``) recast for velocity commands: it measures its
image Jacobian (px per rad) by probing each joint once, moves by
``-J^-1 e`` in one frame period, and refines J with Broyden's rule from every
frame's measured joint motion (encoders) and image motion.  J is kept across
episodes, as the paper's servo keeps it from one fixation to the next.

:class:`VergencePolicy` verges on a textured plane (``scene="textured_plane"``) from the
images alone: it cuts camera 1's fovea, finds it along camera 2's centre row by
normalised cross-correlation (:mod:`headsim.vision.correspondence`), and turns the eye
motor to bring that match onto camera 2's centre column -- where the two foveas'
correlation peaks -- with a gain (px per rad) probed once and refined by secants, as
the servo's.  Neck still.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from headsim.envs.fixate import MOTOR_SPEED_LIMITS_RAD_S
from headsim.vision.correspondence import (
    Match,
    MatchConfig,
    MatchStatus,
    cut_template,
    find,
    row_band,
)
from headsim.vision.markers import find_marker

#: Probe size per joint, rad.
PROBE_RAD = 0.02
#: Smallest joint motion that updates the Jacobian, rad.
MIN_SECANT_RAD = 2e-3


def action_scale(action_space: spaces.Box) -> np.ndarray:
    """rad/s per unit of action: the motors' speed limits for a normalised ``Box(-1, 1)``,
    else 1 (the action is in rad/s)."""
    normalised = bool(np.all(action_space.low == -1.0) and np.all(action_space.high == 1.0))
    return MOTOR_SPEED_LIMITS_RAD_S.astype(float) if normalised else np.ones(3)


class ServoPolicy:
    """The paper's image servo as a policy ``action = policy(observation)``.

    ``action_scale_rad_s``: the speed one unit of action commands (the env's
    ``action_scale_rad_s``); default from the space (:func:`action_scale`).
    """

    def __init__(
        self,
        action_space: spaces.Box,
        period_s: float,
        colour: str = "red",
        action_scale_rad_s: np.ndarray | None = None,
    ) -> None:
        self.action_space = action_space
        self.action_scale_rad_s = (
            action_scale(action_space)
            if action_scale_rad_s is None
            else np.asarray(action_scale_rad_s, float)
        )
        self.period_s = period_s
        self.colour = colour
        self.jacobian: np.ndarray | None = None  # px per rad, rows (u1, u2, v), columns joints
        self._probe = np.zeros((3, 3))
        self._probe_joint = 0
        self._last: tuple[np.ndarray, np.ndarray] | None = None  # (encoders, error)

    def reset(self) -> None:
        """A new episode: forget the last frame, keep the Jacobian."""
        self._last = None

    def _error(self, observation: dict[str, np.ndarray]) -> np.ndarray | None:
        seen = [find_marker(observation[c], self.colour) for c in ("cam1", "cam2")]
        if not all(s.found and s.uv is not None for s in seen):
            return None
        height, width = observation["cam1"].shape[:2]
        u0, v0 = (width - 1) / 2, (height - 1) / 2
        (u1, v1), (u2, v2) = seen[0].uv, seen[1].uv  # type: ignore[misc]
        return np.array([u1 - u0, u2 - u0, (v1 + v2) / 2 - v0])

    def __call__(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        encoders = np.asarray(observation["encoders"], float)
        error = self._error(observation)
        if error is None:
            self._last = None
            return np.zeros(3, np.float32)
        last, self._last = self._last, (encoders, error)
        if self.jacobian is None:
            if last is not None and self._probe_joint > 0:
                joint = self._probe_joint - 1
                moved = encoders[joint] - last[0][joint]
                if abs(moved) > 1e-6:
                    self._probe[:, joint] = (error - last[1]) / moved
            if self._probe_joint == 3:
                self.jacobian = self._probe.copy()
            else:
                action = np.zeros(3)
                action[self._probe_joint] = PROBE_RAD / self.period_s
                self._probe_joint += 1
                return self._clip(action)
        if last is not None:
            dq = encoders - last[0]
            if np.max(np.abs(dq)) >= MIN_SECANT_RAD:
                de = error - last[1]
                self.jacobian = self.jacobian + np.outer(de - self.jacobian @ dq, dq) / (dq @ dq)
        try:
            move = -np.linalg.solve(self.jacobian, error)
        except np.linalg.LinAlgError:
            self.jacobian = None
            self._probe_joint = 0
            return np.zeros(3, np.float32)
        return self._clip(move / self.period_s)

    def _clip(self, speeds_rad_s: np.ndarray) -> np.ndarray:
        """The action commanding ``speeds_rad_s``, within the action space."""
        action = speeds_rad_s / self.action_scale_rad_s
        return np.clip(action, self.action_space.low, self.action_space.high).astype(np.float32)


#: The eye motor's index in the action.
EYE = 2
#: The vergence search's step per frame before a first match, rad.
SEARCH_RAD = 0.05


class VergencePolicy:
    """Image-based vergence on a textured plane, ``action = policy(observation)``.

    ``match``: the fovea's template and its thresholds (default: a 31 px template, the
    correspondence's thresholds); ``row_tolerance_px``: how far off camera 2's centre row
    the match may lie.  ``action_scale_rad_s`` as :class:`ServoPolicy`'s.  No action
    while the match is not OK (low texture, ambiguous, lost), except before the episode's
    first match: LOST, it turns the eyes in by :data:`SEARCH_RAD` a frame
    (``converge_sign``: the eye command's sign that does so, + on the paper's head), for
    a plane so near that camera 1's fovea lies beyond camera 2's searchable row.
    """

    def __init__(
        self,
        action_space: spaces.Box,
        period_s: float,
        action_scale_rad_s: np.ndarray | None = None,
        match: MatchConfig | None = None,
        row_tolerance_px: float = 3.0,
        converge_sign: float = 1.0,
    ) -> None:
        self.action_space = action_space
        self.action_scale_rad_s = (
            action_scale(action_space)
            if action_scale_rad_s is None
            else np.asarray(action_scale_rad_s, float)
        )
        self.period_s = period_s
        self.match = match or MatchConfig(half_px=15)
        self.row_tolerance_px = row_tolerance_px
        self.gain_px_per_rad: float | None = None  # d(disparity) / d(eye encoder)
        self.converge_sign = float(converge_sign)
        self._last: tuple[float, float] | None = None  # (eye encoder, disparity)
        self._matched = False  # this episode

    def reset(self) -> None:
        """A new episode: forget the last frame and match, keep the gain."""
        self._last = None
        self._matched = False

    def fovea_match(self, observation: dict[str, np.ndarray]) -> Match:
        """Camera 1's fovea found along camera 2's centre row."""
        cam1, cam2 = observation["cam1"], observation["cam2"]
        height, width = cam1.shape[:2]
        centre = ((width - 1) / 2, (height - 1) / 2)
        template = cut_template(cam1, centre, self.match)
        band = row_band(centre[1], cam2.shape[1], self.row_tolerance_px)
        return find(template, cam2, band, self.match)

    def disparity_px(self, observation: dict[str, np.ndarray]) -> float | None:
        """Where camera 1's fovea lies in camera 2, from camera 2's centre column, px
        (None: no OK match)."""
        found = self.fovea_match(observation)
        if not found.ok or found.uv is None:
            return None
        return float(found.uv[0] - (observation["cam2"].shape[1] - 1) / 2)

    def __call__(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        eye = float(np.asarray(observation["encoders"], float)[EYE])
        found = self.fovea_match(observation)
        speeds = np.zeros(3)
        if not found.ok or found.uv is None:
            self._last = None
            if found.status is MatchStatus.LOST and not self._matched:
                # Not in camera 2's view yet: a plane nearer than its row reaches.
                speeds[EYE] = self.converge_sign * SEARCH_RAD / self.period_s
            return self._action(speeds)
        self._matched = True
        disparity = float(found.uv[0] - (observation["cam2"].shape[1] - 1) / 2)
        last, self._last = self._last, (eye, disparity)
        if last is not None and abs(eye - last[0]) >= MIN_SECANT_RAD:
            # Broyden's update in one dimension: the secant of the last move.
            self.gain_px_per_rad = (disparity - last[1]) / (eye - last[0])
        if self.gain_px_per_rad is None or abs(self.gain_px_per_rad) < 1e-6:
            speeds[EYE] = PROBE_RAD / self.period_s  # probe: the gain from the next frame
        else:
            speeds[EYE] = -disparity / self.gain_px_per_rad / self.period_s
        return self._action(speeds)

    def _action(self, speeds_rad_s: np.ndarray) -> np.ndarray:
        action = speeds_rad_s / self.action_scale_rad_s
        return np.clip(action, self.action_space.low, self.action_space.high).astype(np.float32)


class RandomPolicy:
    """Uniform random actions from a seeded generator."""

    def __init__(self, action_space: spaces.Box, seed: int = 0) -> None:
        self.action_space = action_space
        self.rng = np.random.default_rng(seed)

    def reset(self) -> None:
        pass

    def __call__(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        low, high = self.action_space.low, self.action_space.high
        return self.rng.uniform(low, high).astype(np.float32)
