"""Recording a run to a Rerun ``.rrd`` file, replayed with ``rerun FILE.rrd``.

A :class:`Recorder` is a :class:`headsim.run.events.Subscriber`: it logs the
experiment's own images and detections as the procedures make them (no
render is made for the record) and the results as they come.  Entity paths
and timelines (README "Scenarios and results" lists them):

- timelines ``frame`` (images rendered in the run, from 0) and ``step``
  (fixations: calibration samples, then measurements, from 0); every entity
  is logged on both;
- ``/world`` (W, z up): ``/world/head`` (Transform3D world_from_head),
  ``/world/head/cam1``, ``/world/head/cam2`` (Transform3D head_from_camera
  and a Pinhole with the true K: the frusta), ``.../image`` (the JPEG image),
  ``.../features`` (the detection), ``.../objects`` (relative positioning),
  ``.../goal`` (the goal column, static), ``/world/optical_axes``,
  ``/world/truth``, ``/world/estimate``, ``/world/error``,
  ``/world/current_target``, ``/world/calibration/positions``,
  ``/world/moving_target/path``, ``/world/areas/lines``, ``/world/areas/objects``;
  the pursuit procedure adds ``/world/pursuit/path`` (the target's path) and
  ``/world/pursuit/estimates`` (every frame's estimate so far), and logs
  ``/world/truth``, ``/world/estimate``, ``/world/error``, the servo offsets
  and ``/measurements/error_mm``, ``.../error_pct_of_depth`` once per frame;
- ``/servo/cam1/u_error_px``, ``/servo/cam2/u_error_px``, ``.../v_error_px``;
  ``/joints/eye_rad``, ``/joints/neck_yaw_rad``, ``/joints/neck_pitch_rad``;
  ``/measurements/error_mm``, ``/measurements/error_pct_of_depth``,
  ``/measurements/renders``, ``/measurements/servo_residual_px``;
- ``/results/scenario``, ``/results/calibration``, ``/results/summary``,
  ``/results/measurements`` (markdown text; each shown by its own view);
- ``/world/model/<body>`` (Transform3D world_from_body when it moved) and
  its geoms (:mod:`headsim.run.mjcf_rerun`): the head and the scene in 3-D.

The stream goes to a file, a running viewer (``--connect``) or a served web
viewer (``--serve``), or several (:class:`headsim.run.rerun_cli.RecordingTarget`).

The stream is written as it goes and flushed after every measurement; it is
closed with its footer when the run ends, also when it is interrupted
(Ctrl-C).  A killed writer leaves a file without footer that the viewer and
``rerun.chunk.RrdReader(...).stream()`` still read (``rerun rrd optimize``
rewrites it).
"""

from __future__ import annotations

import math
from datetime import timedelta
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from headsim.active.events import Detected, FixationStarted, PhaseStarted
from headsim.active.measurement import HeadKnowledge
from headsim.geometry.kinematics import head_to_world
from headsim.run import mjcf_rerun
from headsim.run.events import CalibrationDone, MeasurementRecorded, RunFinished, Stamp
from headsim.run.outcomes import CalibrationReport, MeasurementRecord, RelativeResult, RunResult
from headsim.run.report import summary_text
from headsim.run.rerun_cli import RecordingTarget
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.optics import camera_matrix
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import find_markers

APP_ID = "headsim"
#: JPEG quality of the recorded images (the experiment's own images are exact; these are for people).
JPEG_QUALITY = 75
#: Distance from the image plane to the optical centre of a drawn frustum, m.
FRUSTUM_DEPTH_M = 0.08
#: Longest time logged data waits in the batcher before it is written or streamed.
FLUSH_TICK = timedelta(seconds=1)

_GREEN = (40, 220, 90)
_RED = (235, 60, 50)
_WHITE = (235, 235, 235)
_ORANGE = (255, 160, 30)
_GREY = (150, 150, 150)
#: Target markers are a few mm: drawn in screen points so that they show at any zoom.
_UI_RADIUS_SMALL = rr.components.Radius.ui_points(3.0)
_UI_RADIUS = rr.components.Radius.ui_points(4.0)
_UI_RADIUS_LARGE = rr.components.Radius.ui_points(6.0)


#: The text documents of a recording, each shown by its own view (one per tab).
TEXT_DOCUMENTS = {
    "/results/scenario": "scenario",
    "/results/calibration": "calibration",
    "/results/summary": "summary",
    "/results/measurements": "measurements",
}


def text_views() -> list[rrb.TextDocumentView]:
    """One view per text document; each view's query is its document's path alone."""
    return [
        rrb.TextDocumentView(origin=path, contents="$origin", name=name)
        for path, name in TEXT_DOCUMENTS.items()
    ]


def eye_controls(scenario: Scenario | None = None) -> rrb.EyeControls3D:
    """The 3-D view's starting eye: behind and above the head, looking past it at the targets."""
    head = np.array([0.0, 0.0, 0.21])
    if scenario is not None:
        head = np.array([0.0, 0.0, scenario.settings.neck_d1_m + scenario.settings.neck_a2_m])
    points = [head] + [np.asarray(p, dtype=float) for p in _placements(scenario)]
    targets = np.array(points[1:]) if len(points) > 1 else head + np.array([[0.0, 0.8, 0.0]])
    reach = float(np.max(np.linalg.norm(targets - head, axis=1)))
    look_target = head + 0.6 * (targets.mean(axis=0) - head)
    position = head + reach * np.array([0.35, -0.95, 0.75])
    return rrb.EyeControls3D(
        kind=rrb.Eye3DKind.Orbital,
        position=position,
        look_target=look_target,
        eye_up=[0.0, 0.0, 1.0],
    )


def _placements(scenario: Scenario | None) -> list[tuple[float, float, float]]:
    """World positions of what the scenario places (targets, boards, objects, waypoints), m."""
    if scenario is None:
        return []
    scene = scenario.scene
    points = [t.position_world_m for t in (*scene.targets, *scene.objects)]
    points += [p.position_world_m for p in (scene.chessboard, scene.blocks) if p is not None]
    if scene.moving is not None:
        points += list(scene.moving.waypoints_world_m)
    return points


def blueprint(scenario: Scenario | None = None) -> rrb.Blueprint:
    """The default layout: 3-D view, both camera images, servo and joint traces, results.

    Every text document has a view of its own (tabs), so that no view is
    asked to show more than one document.
    """
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(
                origin="/world",
                name="head, scene and targets (W)",
                eye_controls=eye_controls(scenario),
                defaults=mjcf_rerun.view_defaults(),
            ),
            rrb.Vertical(
                rrb.Horizontal(
                    rrb.Spatial2DView(origin="/world/head/cam1", name="camera 1"),
                    rrb.Spatial2DView(origin="/world/head/cam2", name="camera 2"),
                ),
                rrb.Horizontal(
                    rrb.TimeSeriesView(origin="/servo", name="servo error, px"),
                    rrb.TimeSeriesView(origin="/joints", name="joint encoders, rad"),
                    rrb.TimeSeriesView(origin="/measurements", name="measurements"),
                ),
                rrb.Tabs(*text_views(), active_tab=2),
                row_shares=[3, 2, 2],
            ),
            column_shares=[2, 3],
        ),
        rrb.TimePanel(timeline="frame", state="collapsed"),
        collapse_panels=True,
    )


def recording_id(scenario: Scenario) -> str:
    """Deterministic id: scenario, variant and seed."""
    return f"{scenario.name}{'-fast' if scenario.fast else ''}-seed{scenario.seed}"


class Recorder:
    """Logs a run to ``path`` as it goes; :meth:`close` writes the footer."""

    def __init__(
        self,
        path: str | Path | None,
        scenario: Scenario,
        jpeg_quality: int = JPEG_QUALITY,
        *,
        target: RecordingTarget | None = None,
        recording: str | None = None,
    ):
        """``path``: the .rrd file; or ``target``: a file, a viewer to connect to, a server
        to host (any of them; :mod:`headsim.run.rerun_cli`).  ``recording``: the recording
        id (default :func:`recording_id`)."""
        if target is None:
            if path is None:
                raise ValueError("Recorder needs a path or a target")
            target = RecordingTarget(rrd=Path(path))
        self.target = target
        self.path = target.rrd
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        self.scenario = scenario
        self.jpeg_quality = int(jpeg_quality)
        self.rec = rr.RecordingStream(
            APP_ID,
            recording_id=recording or recording_id(scenario),
            # Chunks end at each flush (every measurement) or after a second: fewer, larger
            # chunks than the default 8 ms tick (each chunk costs about 1 kB in the file).
            batcher_config=rr.ChunkBatcherConfig(flush_tick=FLUSH_TICK),
        )
        # No wall-clock timeline: two runs log the same data.
        self.rec.set_log_time_enabled(False)
        layout = blueprint(scenario)
        sinks: list[rr.FileSink | rr.GrpcSink | rr.GrpcServerSink] = []
        if target.connect_url is not None:
            sinks.append(rr.GrpcSink(target.connect_url))
        if target.serve:
            sinks.append(rr.GrpcServerSink(port=target.grpc_port))
        if sinks and self.path is not None:
            sinks.append(rr.FileSink(self.path))
        if sinks:
            self.rec.set_sinks(*sinks, default_blueprint=layout)  # each sink gets the layout
        elif self.path is not None:
            self.rec.save(self.path, default_blueprint=layout)
        if target.serve:
            # The page only; the data comes from the gRPC server above.
            rr.serve_web_viewer(
                web_port=target.web_port, open_browser=False, connect_to=target.server_url
            )
        self.rec.send_recording_name(scenario.name)
        self.current_frame = 0
        self.current_step = 0
        self.label = ""
        self.phase_name = ""
        self.truth: dict[str, np.ndarray] = {}
        self.estimates: dict[str, tuple[np.ndarray, np.ndarray, bool]] = {}
        self._labels: dict[str, str] = {}
        self.knowledge = HeadKnowledge()
        self.effective_alpha_e = (0.0, 0.0)
        self.world_from_head_start = np.eye(4)
        self.objects: dict[str, str] = {}
        self.closed = False
        self._pursuit_trail: list[np.ndarray] = []
        self.sim: HeadSim | None = None  # the current phase's simulator
        #: Each camera's last whole image in the phase, the backdrop of the windows after it.
        self._last_full: dict[int, np.ndarray] = {}
        self._scene_key: tuple[str, ...] | None = None
        self._body_poses: mjcf_rerun.BodyPoses | None = None
        # Geometry is static when the whole run is in one scene; else logged per phase.
        scenes = {scenario.scene.scene}
        if scenario.experiment.calibration is not None:
            scenes.add("default")
        self._static_geometry = len(scenes) == 1
        self.geometry: list[mjcf_rerun.ModelGeometry] = []
        self._rows: list[str] = []
        self._log_static()

    # -- helpers ------------------------------------------------------------------
    def _time(self) -> None:
        self.rec.set_time("frame", sequence=self.current_frame)
        self.rec.set_time("step", sequence=self.current_step)

    def _log_static(self) -> None:
        s = self.scenario
        self.rec.log("/world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for index, cam in enumerate(names.CAMERAS):
            settings = s.settings.cameras[index]
            # headsim's camera frames are OpenCV's (x right, y down, z forward):
            # Rerun's RDF, so no conversion here (MuJoCo's RUB is converted in headsim.sim.simulator).
            self.rec.log(
                f"/world/head/{cam}",
                rr.Pinhole(
                    image_from_camera=camera_matrix(settings),
                    resolution=[settings.width, settings.height],
                    camera_xyz=rr.ViewCoordinates.RDF,
                    image_plane_distance=FRUSTUM_DEPTH_M,
                ),
                static=True,
            )
            u0, v0 = settings.image_centre
            self.rec.log(
                f"/world/head/{cam}/goal",
                rr.LineStrips2D(
                    [
                        [[u0, 0.0], [u0, settings.height - 1.0]],
                        [[0.0, v0], [settings.width - 1.0, v0]],
                    ],
                    colors=[_ORANGE, _GREY],
                    labels=["goal column u0", "centre row"],
                    show_labels=False,
                ),
                static=True,
            )
        for key, unit in (
            ("error_mm", "mm"),
            ("error_pct_of_depth", "%"),
            ("servo_residual_px", "px"),
        ):
            self.rec.log(
                f"/measurements/{key}", rr.SeriesPoints(names=[f"{key} ({unit})"]), static=True
            )
        for cam in names.CAMERAS:
            for axis in ("u", "v"):
                self.rec.log(
                    f"/servo/{cam}/{axis}_error_px",
                    rr.SeriesLines(names=[f"{cam} {axis} - {axis}0"]),
                    static=True,
                )
        self.rec.log(
            "/results/scenario",
            rr.TextDocument(self._scenario_markdown(), media_type=rr.MediaType.MARKDOWN),
            static=True,
        )
        # Until they exist, the other documents say what will be there (frame 0).
        self._time()
        calibration = self.scenario.experiment.calibration
        for path, text in (
            (
                "/results/calibration",
                "# Calibration\n\n"
                + ("running ..." if calibration else "none: this scenario does not calibrate"),
            ),
            ("/results/summary", "# Summary\n\nwritten when the run ends"),
            ("/results/measurements", "# Measurements\n\nnone yet"),
        ):
            self.rec.log(path, rr.TextDocument(text, media_type=rr.MediaType.MARKDOWN))

    def _scenario_markdown(self) -> str:
        s = self.scenario
        rows = "\n".join(
            f"| cam{k + 1} | {c.width}x{c.height} | {c.kx:.2f} | {c.ky:.2f} | "
            f"{c.principal[0]:.1f}, {c.principal[1]:.1f} | {c.k1:.4f} | {c.mount_yaw_rad:.4f} | {c.noise_std:g} |"
            for k, c in enumerate(s.settings.cameras)
        )
        return (
            f"# {s.name}{' (fast)' if s.fast else ''}\n\n{s.description}\n\n"
            f"procedure `{s.experiment.procedure}`, preset `{s.preset}`, seed {s.seed}, "
            f"baseline {s.settings.baseline_m * 1000:g} mm\n\n"
            "| camera | size | kx | ky | principal | k1 | mount yaw | noise |\n"
            "|---|---|---|---|---|---|---|---|\n" + rows + "\n" + self._real_head_markdown()
        )

    def _real_head_markdown(self) -> str:
        """The imperfections beyond the paper and what the head believes (issue 10)."""
        s = self.scenario.settings
        b = s.believed
        cams = "\n".join(
            f"| cam{k + 1} | {1e3 * c.nodal_offset_m:g} | {1e3 * c.side_offset_m:g} | "
            f"{1e3 * c.eye_axis_tilt_rad:g} | {1e3 * b.nodal_offset_m[k]:g} | {1e3 * b.side_offset_m[k]:g} |"
            for k, c in enumerate(s.cameras)
        )
        return (
            f"\ntruth / belief: baseline {s.baseline_m * 1000:g} / {b.baseline_m * 1000:g} mm, "
            f"neck d1 {s.neck_d1_m * 1000:g} / {b.neck_d1_m * 1000:g} mm, "
            f"a2 {s.neck_a2_m * 1000:g} / {b.neck_a2_m * 1000:g} mm; backlash "
            f"{s.backlash_rad:g} rad; count error {'on' if s.count_error else 'off'}; rendering "
            f"offsamples {s.render.offsamples}, supersample {s.render.supersample}\n\n"
            "| camera | nodal mm | side mm | axis tilt mrad | believed nodal mm | believed side mm |\n"
            "|---|---|---|---|---|---|\n" + cams + "\n"
        )

    def _scene(self, sim: HeadSim) -> None:
        """Log the model's geometry when this sim's model is new to the recording."""
        model = sim.model
        key = tuple(mjcf_rerun.body_name(model, b) for b in range(model.nbody)) + tuple(
            mjcf_rerun.geom_name(model, g) for g in range(model.ngeom)
        )
        if key == self._scene_key:
            return
        if self._scene_key is not None and not self._static_geometry:
            self.rec.log(mjcf_rerun.ROOT, rr.Clear(recursive=True))
        self._scene_key = key
        self.geometry.append(
            mjcf_rerun.log_model_geometry(self.rec, model, static=self._static_geometry)
        )
        self._body_poses = mjcf_rerun.BodyPoses(model)

    def _pose(self, sim: HeadSim) -> None:
        if self._body_poses is not None:
            self._body_poses.log(self.rec, sim.data)
        world_from_head = sim.world_from_head()
        self.rec.log(
            "/world/head",
            rr.Transform3D(translation=world_from_head[:3, 3], mat3x3=world_from_head[:3, :3]),
        )
        origins, vectors = [], []
        target = self.truth.get(self.label)
        for index, cam in enumerate(names.CAMERAS):
            head_from_camera = sim.head_from_camera(index + 1)
            self.rec.log(
                f"/world/head/{cam}",
                rr.Transform3D(
                    translation=head_from_camera[:3, 3], mat3x3=head_from_camera[:3, :3]
                ),
            )
            world_from_camera = sim.world_from_camera(index + 1)
            centre = world_from_camera[:3, 3]
            length = 1.0 if target is None else 1.2 * float(np.linalg.norm(target - centre))
            origins.append(centre)
            vectors.append(world_from_camera[:3, 2] * length)
        self.rec.log(
            "/world/optical_axes",
            rr.Arrows3D(
                origins=origins,
                vectors=vectors,
                colors=[_ORANGE, _ORANGE],
                labels=["cam1", "cam2"],
                show_labels=False,
            ),
        )
        eye = sim.eye_encoder()
        yaw, pitch = sim.neck_encoders()
        for key, value in (("eye_rad", eye), ("neck_yaw_rad", yaw), ("neck_pitch_rad", pitch)):
            self.rec.log(f"/joints/{key}", rr.Scalars([value]))

    # -- the subscriber -----------------------------------------------------------
    def notify(self, event: object, at: Stamp) -> None:
        """Log ``event`` (see :mod:`headsim.run.events`) at ``at``'s frame and step."""
        from headsim.live.gaze import PursuitFrame  # the live pursuit's frames

        if isinstance(event, PhaseStarted):
            self.sim, self._last_full = event.sim, {}
            self.phase(event.name, event.sim, event.knowledge, dict(event.truth_world_m))
        elif isinstance(event, FixationStarted):
            self.step(at.step, event.label)
        elif isinstance(event, ImageTaken) and event.kind is not ImageKind.PREVIEW:
            assert self.sim is not None
            self.rendered(self.sim, event.camera, self._frame_image(event), at.frame)
        elif isinstance(event, Detected):
            assert self.sim is not None
            status = event.status.value
            self.detected(self.sim, event.camera, event.uv_px, status, at.frame)
        elif isinstance(event, MeasurementRecorded):
            self.measured(event.record)
        elif isinstance(event, PursuitFrame):
            self.pursued(event.record, at.frame)
        elif isinstance(event, CalibrationDone):
            self.calibrated(event.report)
        elif isinstance(event, RunFinished):
            self.finished(event.result)

    def _frame_image(self, event: ImageTaken) -> np.ndarray:
        """The image as shown: a window in a full-size frame, around it the camera's last
        whole image at half brightness (not rendered now), or black before there is one."""
        if event.kind is not ImageKind.WINDOW or event.window is None:
            self._last_full[event.camera] = event.image
            return event.image
        assert self.sim is not None
        settings = self.sim.camera_settings(event.camera)
        last = self._last_full.get(event.camera)
        if last is not None and last.shape == (settings.height, settings.width, 3):
            frame = last // 2
        else:
            frame = np.zeros((settings.height, settings.width, 3), dtype=np.uint8)
        window = event.window
        frame[window.y0 : window.y1, window.x0 : window.x1] = event.image
        return frame

    def phase(
        self, name: str, sim: HeadSim, knowledge: HeadKnowledge, truth: dict[str, np.ndarray]
    ) -> None:
        self.phase_name = name
        self.truth = {k: np.asarray(v, dtype=float) for k, v in truth.items()}
        self.estimates = {}
        self.knowledge = knowledge
        self.effective_alpha_e = (
            sim.effective_initial_direction(1),
            sim.effective_initial_direction(2),
        )
        self.world_from_head_start = sim.world_from_head()
        self._time()
        self._scene(sim)
        procedure = self.scenario.experiment.procedure
        self.objects = (
            {o.body: names.RELATIVE_OBJECT_COLOURS[o.body] for o in self.scenario.scene.objects}
            if name == "measurement" and procedure == "relative_positioning"
            else {}
        )
        self._time()
        positions = np.array(list(self.truth.values())).reshape(-1, 3)
        labels = list(self.truth)
        if name == "calibration":
            self.rec.log(
                "/world/calibration/positions",
                rr.Points3D(positions, radii=_UI_RADIUS_SMALL, colors=[_GREY] * len(labels)),
            )
        else:
            self.rec.log("/world/calibration/positions", rr.Clear(recursive=False))
            self.rec.log(
                "/world/truth",
                rr.Points3D(
                    positions,
                    radii=_UI_RADIUS_SMALL,
                    colors=[_WHITE] * len(labels),
                    labels=labels,
                    show_labels=False,
                ),
            )
            self.rec.log("/world/estimate", rr.Clear(recursive=False))
            self.rec.log("/world/error", rr.Clear(recursive=False))
        moving = self.scenario.scene.moving
        if name == "measurement" and moving is not None:
            self.rec.log(
                "/world/moving_target/path",
                rr.LineStrips3D(
                    [np.asarray(moving.waypoints_world_m)], colors=[_GREY], labels=["waypoints"]
                ),
            )
        self._pose(sim)

    def step(self, step: int, label: str) -> None:
        self.current_step, self.label = step, label
        self._time()
        target = self.truth.get(label)
        if target is not None:
            self.rec.log(
                "/world/current_target",
                rr.Points3D([target], radii=_UI_RADIUS_LARGE, colors=[_ORANGE], labels=[label]),
            )

    def rendered(self, sim: HeadSim, camera: int, image: np.ndarray, frame: int) -> None:
        self.current_frame = frame
        self._time()
        self._pose(sim)
        cam = names.CAMERAS[camera - 1]
        ok, jpeg = cv2.imencode(
            ".jpg",
            cv2.cvtColor(image, cv2.COLOR_RGB2BGR),
            [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality],
        )
        if ok:
            self.rec.log(
                f"/world/head/{cam}/image",
                rr.EncodedImage(contents=jpeg.tobytes(), media_type="image/jpeg"),
            )
        # Cleared here; the detection made in this image (if any) follows at the same frame.
        self.rec.log(f"/world/head/{cam}/features", rr.Clear(recursive=False))
        if self.objects:
            found = find_markers(image, self.objects)
            seen = [(k, d.uv) for k, d in found.items() if d.found and d.uv is not None]
            self.rec.log(
                f"/world/head/{cam}/objects",
                rr.Points2D(
                    [uv for _, uv in seen],
                    radii=6.0,
                    colors=[_WHITE] * len(seen),
                    labels=[k for k, _ in seen],
                ),
            )

    def detected(
        self, sim: HeadSim, camera: int, uv: tuple[float, float] | None, status: str, frame: int
    ) -> None:
        cam = names.CAMERAS[camera - 1]
        self.current_frame = frame
        self._time()
        if uv is None:
            self.rec.log(f"/world/head/{cam}/features", rr.Clear(recursive=False))
            return
        self.rec.log(
            f"/world/head/{cam}/features",
            rr.Points2D([uv], radii=5.0, colors=[_GREEN], labels=[self.label]),
        )
        u0, v0 = self.knowledge.reference(sim, camera)
        self.rec.log(f"/servo/{cam}/u_error_px", rr.Scalars([uv[0] - u0]))
        self.rec.log(f"/servo/{cam}/v_error_px", rr.Scalars([uv[1] - v0]))

    def measured(self, record: MeasurementRecord) -> None:
        m = record.measurement
        self.current_step = record.step
        self._time()
        label = m.name
        if record.time_s is not None:
            label += f" t={record.time_s:g}s"
        if self.scenario.experiment.procedure == "calibration":
            label += f" ({record.knowledge})"
        self.estimates[f"{record.step}"] = (m.estimate_world_m, m.truth_world_m, m.ok)
        self._labels[f"{record.step}"] = label
        done = [(k, e, t) for k, (e, t, ok) in self.estimates.items() if ok]
        if done:
            self.rec.log(
                "/world/estimate",
                rr.Points3D(
                    [e for _, e, _ in done],
                    radii=_UI_RADIUS,
                    colors=[_GREEN] * len(done),
                    labels=[self._labels[k] for k, _, _ in done],
                    show_labels=False,
                ),
            )
            self.rec.log(
                "/world/error",
                rr.LineStrips3D([[t, e] for _, e, t in done], colors=[_RED] * len(done)),
            )
        error = float(np.linalg.norm(m.error_head_m))
        if math.isfinite(error):
            self.rec.log("/measurements/error_mm", rr.Scalars([error * 1000.0]))
            self.rec.log("/measurements/error_pct_of_depth", rr.Scalars([m.error_pct_of_depth]))
        self.rec.log("/measurements/renders", rr.Scalars([float(m.renders)]))
        residuals = [abs(r) for r in m.servo_residual_px if math.isfinite(r)]
        if residuals:
            self.rec.log("/measurements/servo_residual_px", rr.Scalars([max(residuals)]))
        self._rows.append(
            f"| {record.step} | {label} | {m.status_text} | {error * 1000.0:.2f} | "
            f"{m.error_pct_of_depth:.3f} | {m.renders} | "
            f"{max(residuals) if residuals else float('nan'):.2f} |"
        )
        self.rec.log(
            "/results/measurements",
            rr.TextDocument(
                "# Measurements\n\n| step | target | status | error mm | % of depth | renders "
                "| residual px |\n|---|---|---|---|---|---|---|\n" + "\n".join(self._rows) + "\n",
                media_type=rr.MediaType.MARKDOWN,
            ),
        )
        self.rec.flush()

    def pursued(self, record: Any, frame: int) -> None:
        """A live pursuit frame: truth, estimate and error on the frame timeline."""
        self.current_frame = frame
        self._time()
        spec = self.scenario.scene.pursuit
        if not self._pursuit_trail and spec is not None:
            times = spec.sample_times(0.02)
            path = [
                spec.path.position(float(t)) for t in times if spec.visibility.visible(float(t))
            ]
            if len(path) > 1:
                self.rec.log(
                    "/world/pursuit/path",
                    rr.LineStrips3D([np.array(path)], colors=[_GREY], labels=["path"]),
                    static=True,
                )
        truth, estimate = record.truth_world_m, record.estimate_world_m
        if truth is not None:
            self.rec.log("/world/truth", rr.Points3D([truth], radii=0.003, colors=[_WHITE]))
        else:
            self.rec.log("/world/truth", rr.Clear(recursive=False))
        for index, cam in enumerate(names.CAMERAS):
            uv = record.uv_px[index]
            if uv is None:
                self.rec.log(f"/world/head/{cam}/features", rr.Clear(recursive=False))
                continue
            self.rec.log(
                f"/world/head/{cam}/features", rr.Points2D([uv], radii=4.0, colors=[_GREEN])
            )
        if record.error_px is not None:
            for index, cam in enumerate(names.CAMERAS):
                self.rec.log(
                    f"/servo/{cam}/u_error_px", rr.Scalars([float(record.error_px[index])])
                )
        if estimate is None or not np.all(np.isfinite(estimate)):
            self.rec.log("/world/estimate", rr.Clear(recursive=False))
            self.rec.log("/world/error", rr.Clear(recursive=False))
            return
        self._pursuit_trail.append(np.asarray(estimate, float))
        self.rec.log("/world/estimate", rr.Points3D([estimate], radii=0.004, colors=[_GREEN]))
        self.rec.log(
            "/world/pursuit/estimates",
            rr.Points3D(np.array(self._pursuit_trail), radii=0.0015, colors=[_GREEN]),
        )
        if truth is not None:
            error = float(np.linalg.norm(estimate - truth))
            self.rec.log("/world/error", rr.LineStrips3D([[truth, estimate]], colors=[_RED]))
            self.rec.log("/measurements/error_mm", rr.Scalars([error * 1000.0]))
            depth = float(np.linalg.norm(truth - self.world_from_head_start[:3, 3]))
            self.rec.log("/measurements/error_pct_of_depth", rr.Scalars([100.0 * error / depth]))

    def calibrated(self, calibration: CalibrationReport) -> None:
        self._time()
        self.rec.log(
            "/results/calibration",
            rr.TextDocument(_calibration_markdown(calibration), media_type=rr.MediaType.MARKDOWN),
        )
        self.rec.flush()

    def finished(self, result: RunResult) -> None:
        self._time()
        if isinstance(result.experiment, RelativeResult):
            self._log_areas(result.experiment)
        text = summary_text(result)
        self.rec.log(
            "/results/summary",
            rr.TextDocument(f"```\n{text}\n```", media_type=rr.MediaType.MARKDOWN),
        )

    def _log_areas(self, e: RelativeResult) -> None:
        """The lines L11, L12, L21, L22 of the two fixations and each object's area."""
        baseline = self.scenario.settings.baseline_m
        s = self.scenario.settings
        strips, labels = [], []
        far = 2.0
        for step_index, alpha in enumerate((e.alpha1_rad, e.alpha2_rad)):
            if not math.isfinite(alpha):
                return
            for camera in (1, 2):
                sign = 1.0 if camera == 1 else -1.0
                yaw = alpha + self.effective_alpha_e[camera - 1]
                start = np.array([-sign * baseline / 2, 0.0, 0.0])
                end = start + far * np.array([sign * math.sin(yaw), 0.0, math.cos(yaw)])
                strips.append(
                    head_to_world(np.array([start, end]), 0.0, 0.0, s.neck_d1_m, s.neck_a2_m)
                )
                labels.append(f"L{camera}{step_index + 1}")
        self.rec.log(
            "/world/areas/lines", rr.LineStrips3D(strips, colors=[_ORANGE] * 4, labels=labels)
        )
        objects = e.objects
        positions = [self.truth[o.name] for o in objects if o.name in self.truth]
        self.rec.log(
            "/world/areas/objects",
            rr.Points3D(
                positions,
                radii=0.008,
                colors=[_GREEN if o.agree else _RED for o in objects],
                labels=[f"{o.name}: S{o.area} (true S{o.true_area})" for o in objects],
            ),
        )

    def close(self) -> None:
        """Flush and write the footer; the file is complete after this."""
        if not self.closed:
            self.closed = True
            self.rec.flush()
            self.rec.disconnect()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _calibration_markdown(report: CalibrationReport) -> str:
    if not report.ok:
        return f"# Calibration\n\n{report.status_text}\n"
    alpha_e, truth_e, paper_e = (
        report.alpha_e_rad,
        report.alpha_e_truth_rad,
        report.alpha_e_paper_rad,
    )
    assert alpha_e is not None and truth_e is not None and paper_e is not None
    rows = "\n".join(
        f"| alpha_e{k + 1} | {alpha_e[k]:.5f} | {truth_e[k]:.5f} | {paper_e[k]:.4f} |"
        for k in range(2)
    )
    text = (
        "# Calibration of the initial directions (Sec. V)\n\n"
        f"{report.fixated} of {report.targets} positions fixated, {report.renders} renders\n\n"
        "| rad | ours | truth | paper |\n|---|---|---|---|\n" + rows + "\n"
    )
    vertical = report.vertical_reference
    if vertical:
        text += "\n| extended | ours | truth |\n|---|---|---|\n" + "\n".join(
            f"| v{k + 1}0 px | {vertical.v0_px[k]:.2f} | {vertical.v0_truth_px[k]:.2f} |\n"
            f"| kx{k + 1}/ky{k + 1} | {vertical.kx_over_ky[k]:.4f} | {vertical.kx_over_ky_truth[k]:.4f} |"
            for k in range(2)
        )
    return text


__all__ = ["APP_ID", "JPEG_QUALITY", "Recorder", "blueprint", "recording_id"]
