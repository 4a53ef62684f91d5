"""``headsim/Fixate-v0``: bring a marker onto both cameras' goal columns with neck and eyes,
or verge on a textured plane.

Observation (``Dict``): ``cam1``, ``cam2`` -- both cameras' RGB images
(default 128 x 96); ``encoders`` -- (neck yaw, neck pitch, eye motor), rad.
Action (``Box``): velocity commands for (neck yaw, neck pitch, eye motor), each
held for one frame period while the motor ramps to it within its acceleration
limit (physics).  ``action_space="normalised"`` (default): ``Box(-1, 1)``, the
share of each motor's speed limit (:data:`MOTOR_SPEED_LIMITS_RAD_S`), as
reinforcement-learning libraries expect; ``"physical"``: rad/s, within those
limits.  ``env.unwrapped.action_scale_rad_s`` is the speed one unit of action
commands.

Reward ``"offsets"`` (default): minus the mean of the absolute image offsets
``(u1 - u10)/(W/2), (u2 - u20)/(W/2), ((v1 + v2)/2 - v0)/(H/2)``, each 1 when
the marker is not seen.  Reward ``"position"``: the head's own Model 1
estimate, taken as if it fixated the marker -- eq. (2) from the eye encoder
with the *believed* baseline and line-of-sight offsets, eq. (3) with the neck
encoders and the *believed* D-H lengths (``belief``; no truth) -- scored
against the truth: minus its 3-D error over the marker's true distance from
the true eyes' centre at rest, capped at 1 (-1 when there is no estimate).

``belief``: the geometry the head believes it has (None: its design, the
undrawn head's baseline and neck, so that a randomised ``baseline_m`` moves the
truth and not the belief).  ``env.unwrapped.belief_sources``: where each
believed quantity came from (``design`` or ``given``; results.json's
``belief.sources``).

Observation and ``info`` carry no truth except ``info["truth_world_m"]``:
``found`` and ``offsets_px`` (the marker's image offsets, px, NaN when not
seen) are measured from the images; ``estimate_world_m`` is the position
reward's estimate (W, m; None when the eyes do not converge); ``time_s`` and
``steps`` are the clock.  ``truth_world_m``: where the marker truly is (W, m;
None when absent), for scoring and analysis only -- no policy may read it.

Episodes: ``reset(seed=..., options=...)`` places the marker at a seeded
random depth and bearing (and, with ``target_speed_m_s`` > 0, on a seeded
straight path); ``randomise`` maps a field to a ``(low, high)`` range drawn
per episode: camera fields (``kx``, ``ky``, ``k1``, ``k2``,
``mount_yaw_rad``, ``mount_pitch_rad``, ``mount_roll_rad``, ``noise_std``;
each camera drawn independently), ``baseline_m``, and the target's
``depth_m``, ``bearing_rad``, ``speed_m_s``.  Terminated when the marker is
within ``tolerance_px`` of the goals in both images; truncated after
``max_steps`` steps.

The target is a red ball (``target_radius_m``, default 20 mm: the scenes' 4 mm
markers are a third of a pixel across at 1.5 m in a 128 x 96 image).

``scene="textured_plane"``: no marker, no room: before a plain background stands a
fronto-parallel plane (a thin box facing W's -y, no shadows), centred straight ahead of
the eyes' centre at rest at a depth ``plane_depth_m`` drawn per episode (default 0.3 to
2 m; ``randomise`` may set it within 0.1..5 m), with a ``texture`` drawn from the
episode's seed (:mod:`headsim.sim.textures`: default ``pink`` 1/f noise, or
``grating``, ``low``, ``repetitive``; the texture's defaults otherwise).  The plane
spans +-45 degrees seen from the eyes at rest, whatever its depth, and one texture
covers it, about one texel per pixel (:func:`plane_texture_px`): only disparity tells
its depth, not the texture's scale.  The target is where eye 1's optical axis (its
goal pixel) meets the scene (``mujoco.mj_ray``, truth).  ``info``:
``vergence_error_deg``, the angle between eye 2's goal ray and the direction from eye 2
to that point (:func:`headsim.runs.landing.vergence_error_deg`; NaN when eye 1's ray
hits nothing), ``depth_m`` (the plane's), ``texture_seed``, and ``truth_world_m`` (that
target); no ``found`` or ``offsets_px``.  Reward ``"vergence"`` (the default there):
minus the vergence error over the camera's half horizontal field of view, capped at 1
(-1 when NaN), as the offsets are shares of half the image: the teacher signal of
active efficient coding, truth that no policy may read; ``"position"`` scores the
Model 1 estimate against that target.  Terminated when the vergence error is within
the angle ``tolerance_px`` subtends at eye 2's focal length.  The vectorised env has
no plane scene.

``multisamples`` is MuJoCo's off-screen multisampling: 0 by default here,
because 4 (the at-rest procedures' setting, edges to a quarter pixel) made a
128 x 96 render about 5 times slower on the CPU renderer (6.5 against 1.3 ms
per image, one run).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import gymnasium
import mujoco
import numpy as np
from gymnasium import spaces

from headsim.active.measurement import HeadKnowledge
from headsim.estimators.model1 import model1
from headsim.head.sim_head import SimHead
from headsim.live.head import EYE_LIMITS, NECK_LIMITS, Frame, LiveConfig, LiveHead
from headsim.live.paths import Static, Waypoints
from headsim.runs.landing import landing, vergence_error_deg
from headsim.sim.heads import HeadModel, shipped
from headsim.sim.model import design, neck_of, on_head
from headsim.sim.settings import (
    BELIEF_KEYS,
    CAMERA_NUMBER_FIELDS,
    IDEAL_FOCAL_PX,
    CameraSettings,
    HeadBelief,
    HeadSettings,
    SettingsError,
)
from headsim.sim.simulator import HeadSim, for_settings
from headsim.sim.textured_scene import LightSettings, RoomSpec, SceneObject
from headsim.sim.textures import TEXTURE_KINDS, TextureSpec, texture_grey, tint_of, to_rgb
from headsim.vision.markers import find_marker


def _encoder_bounds(head: HeadModel) -> np.ndarray:
    """The largest |angle| of the neck yaw, neck pitch and eye joints, rad (models/head.xml's
    for the paper's head, else the head's MJCF)."""
    if head.is_paper:
        return np.array([1.5708, 0.8, 0.7], np.float32)
    assert head.path is not None
    model = mujoco.MjModel.from_xml_path(str(head.path))
    joints = (head.mapping.neck_yaw, head.mapping.neck_pitch, head.mapping.left_eye)
    return np.array([np.abs(model.joint(j).range).max() for j in joints], np.float32)


def _head_at_home(settings: HeadSettings) -> np.ndarray:
    """H's origin in W with the neck at zero, m."""
    neck = neck_of(settings.head)
    return neck.world_from_head(0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)[:3, 3]


TARGET_BODY = "marker_red"
TARGET_COLOUR = "red"
CAMERA_FIELDS = CAMERA_NUMBER_FIELDS  # their order fixes the random draws
HEAD_FIELDS = ("baseline_m",)
TARGET_FIELDS = ("depth_m", "bearing_rad", "speed_m_s")
PLANE_FIELDS = ("plane_depth_m",)
#: What the eyes look at: a marker ball, or a textured plane filling the view.
SCENES = ("marker", "textured_plane")
#: The rewards each scene offers; the first is its default.
SCENE_REWARDS = {"marker": ("offsets", "position"), "textured_plane": ("vergence", "position")}
#: The plane's body, geom and texture (``<name>_texture``).
PLANE_NAME = "gym_plane"
#: The plane's half-size seen from the eyes' centre at rest, deg.
PLANE_HALF_ANGLE_DEG = 45.0
#: Half the plane's thickness (a thin box), m.
PLANE_HALF_THICKNESS_M = 0.005
#: The plane's nearest and farthest depths, m: at 5 m the eyes' vergence is under 2 degrees.
PLANE_DEPTH_LIMITS_M = (0.1, 5.0)
#: The key light shines along the view (the room's default, from above, left the plane dim).
PLANE_LIGHT = LightSettings(direction_world=(0.0, 1.0, -0.3), diffuse=0.7, ambient=0.3)
#: What an action is: the share of each motor's speed limit, or rad/s.
ACTION_SPACES = ("normalised", "physical")
#: The motors' speed limits, rad/s, in the action's order: neck yaw, neck pitch, eye.
MOTOR_SPEED_LIMITS_RAD_S = np.array(
    [NECK_LIMITS.max_speed, NECK_LIMITS.max_speed, EYE_LIMITS.max_speed], np.float32
)


def _check_ranges(randomise: dict[str, Any]) -> dict[str, tuple[float, float]]:
    allowed = (*CAMERA_FIELDS, *HEAD_FIELDS, *TARGET_FIELDS, *PLANE_FIELDS)
    ranges = {}
    for name, bounds in randomise.items():
        if name not in allowed:
            raise SettingsError(f"randomise: unknown field {name!r}; allowed: {', '.join(allowed)}")
        lo, hi = (float(b) for b in bounds)
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            raise SettingsError(
                f"randomise.{name} must be (low, high) with low <= high, got {bounds!r}"
            )
        low, high = PLANE_DEPTH_LIMITS_M
        if name == "plane_depth_m" and not (low <= lo and hi <= high):
            raise SettingsError(
                f"randomise.plane_depth_m must lie within [{low}, {high}] m, got {bounds!r}"
            )
        ranges[name] = (lo, hi)
    return ranges


def plane_texture_px(focal_px: float) -> int:
    """The plane texture's side: the power of two (64..2048) that gives at least one texel
    per pixel at the plane's centre seen straight on with focal length ``focal_px``."""
    need = 2.0 * math.tan(math.radians(PLANE_HALF_ANGLE_DEG)) * focal_px
    return int(min(max(2 ** math.ceil(math.log2(need)), 64), 2048))


def _draw(rng: np.random.Generator, ranges: dict[str, tuple[float, float]], name: str) -> float:
    lo, hi = ranges[name]
    return float(rng.uniform(lo, hi)) if hi > lo else lo


def draw_settings(
    rng: np.random.Generator, base: HeadSettings, ranges: dict[str, tuple[float, float]]
) -> HeadSettings:
    """An episode's head: each camera's and the head's randomised fields drawn from
    ``ranges`` (in :data:`CAMERA_FIELDS`' order, camera 1 first), then its noise seed."""
    cameras = []
    for cam in base.cameras:
        changes: dict[str, Any] = {f: _draw(rng, ranges, f) for f in CAMERA_FIELDS if f in ranges}
        cameras.append(replace(cam, **changes))
    head: dict[str, Any] = {f: _draw(rng, ranges, f) for f in HEAD_FIELDS if f in ranges}
    seed_noise = int(rng.integers(0, 2**31 - 1))
    if all(c.noise_std == 0 for c in cameras):
        seed_noise = 0  # noiseless images do not depend on it: keep the renderer
    return replace(base, cameras=(cameras[0], cameras[1]), seed=seed_noise, **head)


def draw_marker_path(
    rng: np.random.Generator,
    settings: HeadSettings,
    ranges: dict[str, tuple[float, float]],
    options: dict[str, Any],
    duration_s: float,
) -> Waypoints | Static:
    """An episode's marker: at a drawn depth and bearing from the head at home (or at
    ``options["target_world_m"]``), still or on a straight path at a drawn speed."""
    depth = _draw(rng, ranges, "depth_m")
    azimuth, elevation = _draw(rng, ranges, "bearing_rad"), _draw(rng, ranges, "bearing_rad")
    start = _head_at_home(settings) + depth * np.array(
        [
            math.sin(azimuth) * math.cos(elevation),
            math.cos(azimuth) * math.cos(elevation),
            math.sin(elevation),
        ]
    )
    if "target_world_m" in options:
        start = np.asarray(options["target_world_m"], float)
    speed = _draw(rng, ranges, "speed_m_s")
    if speed > 0:
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        end = start + direction * speed * duration_s
        return Waypoints((tuple(start), tuple(end)), (speed,))
    return Static(tuple(start))


def marker_goals(settings: HeadSettings) -> np.ndarray:
    """Where the marker should be seen: (u1, u2, mean v) of the cameras' image centres, px."""
    (u10, v10), (u20, v20) = (c.image_centre for c in settings.cameras)
    return np.array([u10, u20, (v10 + v20) / 2])


def offsets_reward(offsets_px: np.ndarray, found: np.ndarray, settings: HeadSettings) -> np.ndarray:
    """Reward ``"offsets"`` of rows of image offsets (m, 3): minus the mean share of half
    the image, each capped at 1; -1 where the marker is not seen."""
    cam = settings.cameras[0]
    scale = np.array([cam.width / 2, cam.width / 2, cam.height / 2])
    shares = np.minimum(np.abs(offsets_px) / scale, 1.0)
    return np.where(found, -np.mean(np.where(found[:, None], shares, 0.0), axis=1), -1.0)


def position_reward(
    estimate_world_m: np.ndarray, truth_world_m: np.ndarray, settings: HeadSettings
) -> np.ndarray:
    """Reward ``"position"`` of rows (m, 3; NaN: none): minus the estimate's 3-D error over
    the truth's distance from the head at home, capped at 1; -1 without either.
    Scoring only: the truth judges the estimate, it never enters it."""
    distance = np.linalg.norm(truth_world_m - _head_at_home(settings), axis=1)
    error = np.linalg.norm(estimate_world_m - truth_world_m, axis=1)
    reward = -np.minimum(error / np.where(distance > 0, distance, 1.0), 1.0)
    return np.where(np.isnan(reward), -1.0, reward)


def estimate_world(
    encoders_rad: np.ndarray, settings: HeadSettings, knowledge: HeadKnowledge
) -> np.ndarray:
    """The head's Model 1 estimates from rows of (neck yaw, neck pitch, eye) encoder
    readings (m, 3) and its belief, as if fixated: (m, 3) in W, m; NaN where the eyes do
    not converge."""
    belief = knowledge.head_belief_of(settings)
    estimate = model1(
        encoders_rad[:, 2],
        belief.baseline_m,
        alpha_e=knowledge.alpha_e,
        los_offset_m=knowledge.line_of_sight_offsets_of(settings),
    )
    neck = neck_of(settings.head)
    world = np.asarray(
        neck.head_to_world(
            estimate.positions,
            encoders_rad[:, 0],
            encoders_rad[:, 1],
            belief.neck_d1_m,
            belief.neck_a2_m,
        ),
        float,
    ).reshape(-1, 3)
    return np.where(np.asarray(estimate.valid, bool)[:, None], world, np.nan)


class FixateEnv(gymnasium.Env):
    """Fixate a marker with the live head (see the module docstring)."""

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 30}  # noqa: RUF012 (gymnasium.Env declares it an instance attribute)

    def __init__(
        self,
        width: int = 128,
        height: int = 96,
        frame_rate_hz: float = 30.0,
        latency_frames: int = 0,
        max_steps: int = 50,
        reward: str | None = None,
        tolerance_px: float = 1.0,
        randomise: dict[str, Any] | None = None,
        target_radius_m: float = 0.02,
        multisamples: int = 0,
        render_mode: str | None = None,
        belief: HeadBelief | None = None,
        action_space: str = "normalised",
        head: str | HeadModel = "paper",
        scene: str = "marker",
        texture: str = "pink",
    ) -> None:
        if scene not in SCENES:
            raise SettingsError(f"scene must be one of {', '.join(SCENES)}, got {scene!r}")
        if texture not in TEXTURE_KINDS:
            raise SettingsError(
                f"texture must be one of {', '.join(TEXTURE_KINDS)}, got {texture!r}"
            )
        if reward is None:
            reward = SCENE_REWARDS[scene][0]
        if action_space not in ACTION_SPACES:
            raise SettingsError(
                f"action_space must be one of {', '.join(ACTION_SPACES)}, got {action_space!r}"
            )
        if reward not in SCENE_REWARDS[scene]:
            raise SettingsError(
                f"reward for scene {scene!r} must be one of {', '.join(SCENE_REWARDS[scene])}, "
                f"got {reward!r}"
            )
        if render_mode not in (None, "rgb_array"):
            raise SettingsError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        if not (isinstance(max_steps, int) and max_steps >= 1):
            raise SettingsError(f"max_steps must be an integer >= 1, got {max_steps!r}")
        if not (math.isfinite(target_radius_m) and 0.001 <= target_radius_m <= 0.1):
            raise SettingsError(
                f"target_radius_m must be within [0.001, 0.1] m, got {target_radius_m}"
            )
        if multisamples not in (0, 2, 4, 8):
            raise SettingsError(f"multisamples must be 0, 2, 4 or 8, got {multisamples!r}")
        if not (belief is None or isinstance(belief, HeadBelief)):
            raise SettingsError(f"belief must be a HeadBelief or None, got {belief!r}")
        self.target_radius_m = float(target_radius_m)
        self.multisamples = multisamples
        self.render_mode = render_mode
        self.reward_kind = reward
        self.scene = scene
        self.texture = texture
        self.max_steps = max_steps
        self.tolerance_px = float(tolerance_px)
        self.live_config = LiveConfig(frame_rate_hz=frame_rate_hz, latency_frames=latency_frames)
        head_model = shipped(head) if isinstance(head, str) else head
        # The head's own field of view (the paper's: 45 degrees vertical) at this image size.
        own = None if head_model.is_paper else design(head_model).cameras[0]
        focal = (IDEAL_FOCAL_PX / 480.0 if own is None else own.fy_px / own.height) * height
        camera = CameraSettings(width=width, height=height, kx=focal, ky=focal)
        self.base_settings = replace(
            on_head(HeadSettings(cameras=(camera, camera), belief=belief), head_model),
            cameras=(camera, camera),
        )
        #: Where each believed quantity came from (:func:`belief_sources`).
        self.belief_sources = dict.fromkeys(BELIEF_KEYS, "design" if belief is None else "given")
        if belief is None:  # the design's, fixed: a drawn baseline_m is not believed
            self.base_settings = replace(self.base_settings, belief=self.base_settings.believed)
        self.knowledge = HeadKnowledge()  # uncalibrated: the simulator's belief, no alpha_e
        self.defaults = {
            "depth_m": (0.5, 1.5),
            "bearing_rad": (-0.15, 0.15),
            "speed_m_s": (0.0, 0.0),
            "plane_depth_m": (0.3, 2.0),
        }
        self._room: RoomSpec | None = None
        if scene == "textured_plane":
            # A thin box, not a MuJoCo plane: an OpenGL context builds a plane's grid once,
            # at its size then, while a box is scaled at every render (_place_plane sizes it).
            # Its face toward the head carries the whole texture, whatever its size.
            plane = SceneObject(
                PLANE_NAME,
                "box",
                (1.0, PLANE_HALF_THICKNESS_M, 1.0),
                (0.0, 1.0, 0.0),
                TextureSpec(texture, size_px=plane_texture_px(focal)),
            )
            # No room around it: behind a plane that fills the view it doubled a render's
            # cost (2.9 against 5.7 ms a stereo pair at 128 x 96, one run).
            self._room = RoomSpec(objects=(plane,), light=PLANE_LIGHT, plain=True)
        self._plane: dict[str, Any] = {}
        self.randomise = _check_ranges(randomise or {})
        image = spaces.Box(0, 255, (height, width, 3), np.uint8)
        low = -_encoder_bounds(head_model)
        self.observation_space = spaces.Dict(
            {
                "cam1": image,
                "cam2": image,
                "encoders": spaces.Box(low, -low, (3,), np.float32),
            }
        )
        limits = MOTOR_SPEED_LIMITS_RAD_S
        #: The speed one unit of action commands to each motor, rad/s.
        self.action_scale_rad_s = limits if action_space == "normalised" else np.ones(3, np.float32)
        bound = limits / self.action_scale_rad_s
        self.action_space: spaces.Box = spaces.Box(-bound, bound, (3,), np.float32)
        self._sim: HeadSim | None = None
        self._settings: HeadSettings | None = None
        self._live: LiveHead | None = None
        self._frame: Frame | None = None
        self._steps = 0

    # -- episodes --------------------------------------------------------------
    @property
    def period_s(self) -> float:
        return self.live_config.period_s

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        options = options or {}
        ranges = self.episode_ranges(options)
        settings = draw_settings(self.np_random, self.base_settings, ranges)
        if self._sim is None or settings != self._settings:
            if self._sim is not None:
                self._sim.close()
            if self._room is None:
                self._sim = for_settings(settings)
            else:
                self._sim = for_settings(settings, scene="base", room=self._room)
            self._settings = settings
            self.prepare_model(self._sim.model)
        sim = self._sim
        sim.reset()
        if self._room is not None:
            self._place_plane(sim, _draw(self.np_random, ranges, "plane_depth_m"))
            self._live = LiveHead(SimHead(sim), self.live_config)
            self._steps = 0
            self._frame = self._live.capture()
            return self._observation(), self._info(self._measure())
        path = draw_marker_path(
            self.np_random, settings, ranges, options, self.max_steps * self.period_s
        )
        self._live = LiveHead(SimHead(sim), self.live_config, target_body=TARGET_BODY, path=path)
        self._steps = 0
        self._frame = self._live.capture()
        return self._observation(), self._info(self._measure())

    def step(
        self, action: np.ndarray
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        if self._live is None or self._frame is None:
            raise RuntimeError("call reset() before step()")
        space = self.action_space
        speeds = np.clip(np.asarray(action, float), space.low, space.high) * self.action_scale_rad_s

        def command(motors, _now: float) -> None:
            for index, speed in enumerate(speeds):
                motors.set_velocity(index, float(speed))

        if self.live_config.latency_frames == 0:
            self._live.now(command)
        else:
            self._live.send(command, self._frame)
        self._frame = self._live.capture()
        self._steps += 1
        measured = self._measure()
        if self._room is None:
            offsets, found = measured["offsets_px"], measured["found"]
            terminated = bool(found and np.all(np.abs(offsets) <= self.tolerance_px))
        else:
            error = measured["vergence_error_deg"]
            terminated = bool(error <= self._angle_deg(self.tolerance_px))  # False when NaN
        truncated = bool(not terminated and self._steps >= self.max_steps)
        return (
            self._observation(),
            self._reward(measured),
            terminated,
            truncated,
            self._info(measured),
        )

    def episode_ranges(self, options: dict[str, Any]) -> dict[str, tuple[float, float]]:
        """The ranges an episode's fields are drawn from: the defaults, the env's
        ``randomise``, then ``options["randomise"]``."""
        return {**self.defaults, **self.randomise, **_check_ranges(options.get("randomise", {}))}

    def prepare_model(self, model: mujoco.MjModel) -> None:
        """This env's own model: its target's size and the renderer's multisampling."""
        if self._room is None:
            geom = model.geom(TARGET_BODY)
            model.geom_size[geom.id, 0] = self.target_radius_m
            model.geom_rbound[geom.id] = self.target_radius_m
        # Read when the renderer is made, at the first render (after this).
        model.vis.quality.offsamples = self.multisamples

    def _place_plane(self, sim: HeadSim, depth_m: float) -> None:
        """The episode's plane: ``depth_m`` straight ahead of the eyes' centre at rest,
        spanning +-:data:`PLANE_HALF_ANGLE_DEG`, with a texture from the episode's seed."""
        seed = int(self.np_random.integers(0, 2**31 - 1))
        texture_id = sim.model.texture(f"{PLANE_NAME}_texture").id
        spec = TextureSpec(self.texture, seed=seed, size_px=int(sim.model.tex_width[texture_id]))
        sim.set_texture(f"{PLANE_NAME}_texture", to_rgb(texture_grey(spec), tint_of(seed)))
        eyes = (sim.truth.world_from_camera(1)[:3, 3] + sim.truth.world_from_camera(2)[:3, 3]) / 2
        half = depth_m * math.tan(math.radians(PLANE_HALF_ANGLE_DEG))
        front = np.array([0.0, depth_m + PLANE_HALF_THICKNESS_M, 0.0])
        sim.model.body_pos[sim.model.body(PLANE_NAME).id] = eyes + front
        geom = sim.model.geom(PLANE_NAME).id
        sim.model.geom_size[geom] = (half, PLANE_HALF_THICKNESS_M, half)
        sim.model.geom_rbound[geom] = math.sqrt(2 * half**2 + PLANE_HALF_THICKNESS_M**2)
        mujoco.mj_forward(sim.model, sim.data)
        self._plane = {"depth_m": depth_m, "texture_seed": seed}

    def _angle_deg(self, pixels: float) -> float:
        """``pixels`` from eye 2's image centre seen as an angle, deg."""
        assert self._settings is not None
        return math.degrees(math.atan(pixels / self._settings.cameras[1].kx))

    # -- measurements ------------------------------------------------------------
    def _goals(self) -> np.ndarray:
        assert self._settings is not None
        return marker_goals(self._settings)

    def _measure(self) -> dict[str, Any]:
        assert self._frame is not None
        if self._room is not None:
            return self._measure_plane()
        seen = [find_marker(image, TARGET_COLOUR) for image in self._frame.images]
        found = all(s.found and s.uv is not None for s in seen)
        offsets = np.full(3, np.nan)
        if found:
            (u1, v1), (u2, v2) = seen[0].uv, seen[1].uv  # type: ignore[misc]
            offsets = np.array([u1, u2, (v1 + v2) / 2]) - self._goals()
        return {
            "found": found,
            "offsets_px": offsets,
            "estimate_world_m": self._estimate(),
            "truth_world_m": self._frame.truth_target_world_m,
        }

    def _measure_plane(self) -> dict[str, Any]:
        """Truth, for the reward and info only: where eye 1's goal ray meets the scene and
        eye 2's vergence error on it."""
        assert self._sim is not None
        goal1, goal2 = self._goals_uv()
        one, two = landing(self._sim, 1, goal1), landing(self._sim, 2, goal2)
        error = (
            math.nan
            if one.point_world_m is None
            else vergence_error_deg(two.origin_world_m, two.direction_world, one.point_world_m)
        )
        return {
            "vergence_error_deg": error,
            "estimate_world_m": self._estimate(),
            "truth_world_m": one.point_world_m,
        }

    def _goals_uv(self) -> tuple[tuple[float, float], tuple[float, float]]:
        assert self._settings is not None
        one, two = (c.image_centre for c in self._settings.cameras)
        return (float(one[0]), float(one[1])), (float(two[0]), float(two[1]))

    def _estimate(self) -> np.ndarray | None:
        """The head's Model 1 estimate from the encoders and its belief (W, m), as if fixated."""
        assert self._frame is not None and self._settings is not None
        encoders = self._frame.encoders_rad.astype(float)[None, :]
        estimate = estimate_world(encoders, self._settings, self.knowledge)[0]
        return None if np.isnan(estimate).any() else estimate  # eyes parallel or diverging

    def _reward(self, measured: dict[str, Any]) -> float:
        assert self._frame is not None and self._settings is not None
        if self.reward_kind == "offsets":
            found = np.array([measured["found"]])
            return float(offsets_reward(measured["offsets_px"][None, :], found, self._settings)[0])
        if self.reward_kind == "vergence":
            error = measured["vergence_error_deg"]
            if math.isnan(error):
                return -1.0
            half_view_deg = self._angle_deg(self._settings.cameras[1].width / 2)
            return -min(error / half_view_deg, 1.0)
        estimate, truth = measured["estimate_world_m"], measured["truth_world_m"]
        rows = [
            np.full(3, np.nan) if v is None else np.asarray(v, float) for v in (estimate, truth)
        ]
        return float(position_reward(rows[0][None, :], rows[1][None, :], self._settings)[0])

    def _observation(self) -> dict[str, np.ndarray]:
        assert self._frame is not None
        return {
            "cam1": self._frame.images[0],
            "cam2": self._frame.images[1],
            "encoders": self._frame.encoders_rad.astype(np.float32),
        }

    def _info(self, measured: dict[str, Any]) -> dict[str, Any]:
        assert self._frame is not None
        truth = measured["truth_world_m"]
        estimate = measured["estimate_world_m"]
        info: dict[str, Any] = (
            {"found": measured["found"], "offsets_px": measured["offsets_px"]}
            if self._room is None
            else {"vergence_error_deg": measured["vergence_error_deg"], **self._plane}
        )
        return {
            **info,
            "estimate_world_m": None if estimate is None else estimate.copy(),
            "time_s": self._frame.time_s,
            "truth_world_m": None if truth is None else truth.copy(),  # truth: scoring only
            "steps": self._steps,
        }

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array" or self._frame is None:
            return None
        return np.concatenate(self._frame.images, axis=1)

    def close(self) -> None:
        if self._sim is not None:
            self._sim.close()
            self._sim = None


__all__ = [
    "ACTION_SPACES",
    "MOTOR_SPEED_LIMITS_RAD_S",
    "SCENES",
    "SCENE_REWARDS",
    "TARGET_BODY",
    "TARGET_COLOUR",
    "FixateEnv",
    "draw_marker_path",
    "draw_settings",
    "estimate_world",
    "marker_goals",
    "offsets_reward",
    "plane_texture_px",
    "position_reward",
]
