"""Recording a run to a Rerun ``.rrd`` file, replayed with ``rerun FILE.rrd``.

A :class:`Recorder` is a :class:`headsim.runs.events.Subscriber`: it logs the
experiment's own images and detections as the procedures make them (no
render is made for the record) and the results as they come.  Entity paths
and timelines (docs/how-to/record.md lists them):

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
  the live head's frames (:meth:`Recorder.pursued`) add
  ``/world/pursuit/estimates`` (every frame's estimate so far), and log
  ``/world/truth``, ``/world/estimate``, ``/world/error``, the servo offsets
  and ``/measurements/error_mm``, ``.../error_pct_of_depth`` once per frame;
- ``/servo/cam1/u_error_px``, ``/servo/cam2/u_error_px``, ``.../v_error_px``;
  ``/joints/eye_rad``, ``/joints/neck_yaw_rad``, ``/joints/neck_pitch_rad``;
  ``/measurements/error_mm``, ``/measurements/error_pct_of_depth``,
  ``/measurements/renders``, ``/measurements/servo_residual_px``;
- ``/results/scenario``, ``/results/calibration``, ``/results/summary``,
  ``/results/measurements`` (markdown text; each shown by its own view);
- ``/world/model/<body>`` (Transform3D world_from_body when it moved) and
  its geoms (:mod:`headsim.runs.mjcf_rerun`): the head and the scene in 3-D.

The :class:`Recorder` follows the events and logs the head, its scene and the
results; the rows logged with every image are kept and sent as columns
(:class:`RowColumns`).  The layout, the palette and the text documents are in
:mod:`headsim.runs.recording_layout`.

The stream goes to a file, a running viewer (``--connect``) or a served web
viewer (``--serve``), or several (:class:`headsim.runs.rerun_cli.RecordingTarget`).

The stream is written as it goes and flushed after every measurement; it is
closed with its footer when the run ends, also when it is interrupted
(Ctrl-C).  A killed writer leaves a file without footer that the viewer and
``rerun.chunk.RrdReader(...).stream()`` still read (``rerun rrd optimize``
rewrites it).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from datetime import timedelta
from pathlib import Path
from typing import Any

import numpy as np
import rerun as rr

from headsim.active.calibration_report import CalibrationReport
from headsim.active.events import Detected, FixationStarted, PhaseStarted
from headsim.active.measurement import HeadKnowledge
from headsim.errors import interrupted
from headsim.procedures.contract import get
from headsim.runs import mjcf_rerun
from headsim.runs.events import CalibrationDone, MeasurementRecorded, RunFinished, Stamp
from headsim.runs.outcomes import MeasurementRecord, RunOutcome
from headsim.runs.recording_layout import (
    GREEN,
    GREY,
    ORANGE,
    RED,
    UI_RADIUS,
    UI_RADIUS_LARGE,
    UI_RADIUS_SMALL,
    WHITE,
    blueprint,
    calibration_markdown,
    recording_id,
    scenario_markdown,
)
from headsim.runs.recording_room import RoomRecording, log_jpeg
from headsim.runs.rerun_cli import (
    INTERRUPTED_VIEWER_WAIT_S,
    VIEWER_WAIT_S,
    RecordingTarget,
    ViewerUnreachable,
    check_viewer,
    flush_to_viewer,
    viewer_stream_closed,
    viewer_stream_opened,
)
from headsim.runs.summary import summary_text
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.optics import camera_matrix
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import find_markers

APP_ID = "headsim"
#: JPEG quality of the recorded images (the experiment's own images are exact; these are for people).
JPEG_QUALITY = 75
#: Rows kept for :class:`RowColumns` before they are sent without waiting for the next
#: measurement (a calibration, a long pursuit): about 40 images' poses and servo errors.
MAX_KEPT_ROWS = 500
#: Longest time logged data waits in the batcher before it is written or streamed.
FLUSH_TICK = timedelta(seconds=1)
#: Distance from the image plane to the optical centre of a drawn frustum, m.
FRUSTUM_DEPTH_M = 0.08


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
        to host (any of them; :mod:`headsim.runs.rerun_cli`).  ``recording``: the recording
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
        if target.connect_url is not None:
            check_viewer(target.connect_url)  # before Rerun's stream, which would wait for ever
        #: Whether the viewer stopped answering: the stream is then not flushed again.
        self._viewer_lost = False
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
            if target.connect_url is not None:
                viewer_stream_opened()
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
        self._measured: set[tuple[str, float | None, str]] = set()
        self.knowledge = HeadKnowledge()
        self.effective_alpha_e = (0.0, 0.0)
        self.world_from_head_start = np.eye(4)
        self.objects: dict[str, str] = {}
        self.closed = False
        self._frame_estimates: list[np.ndarray] = []
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
        self._kept_rows = RowColumns()
        # JPEG encoding and sending the kept rows run on one thread beside the run's
        # (OpenCV's encoder lets the renders go on meanwhile), in the order given.
        self._background = ThreadPoolExecutor(1, thread_name_prefix="headsim-recording")
        self._pending: list[Future[None]] = []
        self._log_static()
        #: A room run's foveas, matches and landings (:mod:`headsim.runs.recording_room`).
        self.room = (
            RoomRecording(self.rec, self._later, self.jpeg_quality)
            if scenario.scene.room is not None
            else None
        )

    # -- the subscriber -----------------------------------------------------------
    def notify(self, event: object, at: Stamp) -> None:
        """Log ``event`` (see :mod:`headsim.runs.events`) at ``at``'s frame and step."""
        from headsim.live.gaze import PursuitFrame  # the live pursuit's frames

        if isinstance(event, PhaseStarted):
            self.sim, self._last_full = event.sim, {}
            self.phase(event.name, event.sim, event.knowledge, dict(event.truth_world_m))
        elif isinstance(event, FixationStarted):
            self.step(at.step, event.label)
        elif isinstance(event, ImageTaken) and event.kind is not ImageKind.PREVIEW:
            assert self.sim is not None
            image = self._frame_image(event)
            self.rendered(self.sim, event.camera, image, at.frame)
            if self.room is not None:
                self.room.image(event.camera, image, at.frame, self.current_step)
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
        if self.room is not None:  # after the recorder: at the time it set
            self.room.notify(event, at)

    def _frame_image(self, event: ImageTaken) -> np.ndarray:
        """The image as shown: a window in a full-size frame, around it the camera's last
        whole image at half brightness (not rendered now), or black before there is one."""
        if event.window is None:
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
        self._send_kept_rows()
        self.phase_name = name
        self.truth = {k: np.asarray(v, dtype=float) for k, v in truth.items()}
        self.estimates = {}
        self.knowledge = knowledge
        self.effective_alpha_e = (
            sim.truth.effective_initial_direction(1),
            sim.truth.effective_initial_direction(2),
        )
        self.world_from_head_start = sim.truth.world_from_head()
        self._time()
        self._scene(sim)
        self.objects = (
            {o.body: names.RELATIVE_OBJECT_COLOURS[o.body] for o in self.scenario.scene.objects}
            if name == "measurement"
            else {}
        )
        self._time()
        positions = np.array(list(self.truth.values())).reshape(-1, 3)
        labels = list(self.truth)
        if name == "calibration":
            self.rec.log(
                "/world/calibration/positions",
                rr.Points3D(positions, radii=UI_RADIUS_SMALL, colors=[GREY] * len(labels)),
            )
        else:
            self.rec.log("/world/calibration/positions", rr.Clear(recursive=False))
            self.rec.log(
                "/world/truth",
                rr.Points3D(
                    positions,
                    radii=UI_RADIUS_SMALL,
                    colors=[WHITE] * len(labels),
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
                    [np.asarray(moving.waypoints_world_m)], colors=[GREY], labels=["waypoints"]
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
                rr.Points3D([target], radii=UI_RADIUS_LARGE, colors=[ORANGE], labels=[label]),
            )

    def rendered(self, sim: HeadSim, camera: int, image: np.ndarray, frame: int) -> None:
        self.current_frame = frame
        self._time()
        self._pose(sim)
        if len(self._kept_rows) >= MAX_KEPT_ROWS:
            self._send_kept_rows()
        cam = names.CAMERAS[camera - 1]
        self._later(self._log_image, cam, image, frame, self.current_step)
        # No detection at this frame (the last one goes); the one made in this image, if any,
        # follows at the same frame.
        self._features(cam, frame, None)
        if self.objects:
            found = find_markers(image, self.objects)
            seen = [(k, d.uv) for k, d in found.items() if d.found and d.uv is not None]
            self.rec.log(
                f"/world/head/{cam}/objects",
                rr.Points2D(
                    [uv for _, uv in seen],
                    radii=6.0,
                    colors=[WHITE] * len(seen),
                    labels=[k for k, _ in seen],
                ),
            )

    def _log_image(self, cam: str, image: np.ndarray, frame: int, step: int) -> None:
        """The image as a JPEG (on the recording's thread: its own time)."""
        log_jpeg(self.rec, f"/world/head/{cam}/image", image, frame, step, self.jpeg_quality)

    def _features(self, cam: str, frame: int, uv: tuple[float, float] | None) -> None:
        """The detection in the camera's image at ``frame`` (None: none, the last one goes)."""
        found = [] if uv is None else [uv]
        self._kept_rows.add(
            f"/world/head/{cam}/features",
            frame,
            self.current_step,
            rr.Points2D,
            instances=None,
            positions=found,
            radii=[5.0] * len(found),
            colors=[GREEN] * len(found),
            labels=[self.label] * len(found),
        )

    def detected(
        self, sim: HeadSim, camera: int, uv: tuple[float, float] | None, status: str, frame: int
    ) -> None:
        cam = names.CAMERAS[camera - 1]
        self.current_frame = frame
        self._time()
        self._features(cam, frame, uv)
        if uv is None:
            return
        u0, v0 = self.knowledge.reference(sim, camera)
        for axis, error in (("u", uv[0] - u0), ("v", uv[1] - v0)):
            self._kept_rows.add(
                f"/servo/{cam}/{axis}_error_px", frame, self.current_step, rr.Scalars, scalars=error
            )

    # -- the results ---------------------------------------------------------------
    def measured(self, record: MeasurementRecord) -> None:
        m = record.measurement
        self.current_step = record.step
        self._time()
        label = m.name
        if record.time_s is not None:
            label += f" t={record.time_s:g}s"
        seen = {k for n, t, k in self._measured if (n, t) == (m.name, record.time_s)}
        if seen - {record.knowledge}:  # measured again knowing more (before and after)
            label += f" ({record.knowledge})"
        self._measured.add((m.name, record.time_s, record.knowledge))
        self.estimates[f"{record.step}"] = (m.estimate_world_m, m.truth_world_m, m.ok)
        self._labels[f"{record.step}"] = label
        done = [(k, e, t) for k, (e, t, ok) in self.estimates.items() if ok]
        if done:
            self.rec.log(
                "/world/estimate",
                rr.Points3D(
                    [e for _, e, _ in done],
                    radii=UI_RADIUS,
                    colors=[GREEN] * len(done),
                    labels=[self._labels[k] for k, _, _ in done],
                    show_labels=False,
                ),
            )
            self.rec.log(
                "/world/error",
                rr.LineStrips3D([[t, e] for _, e, t in done], colors=[RED] * len(done)),
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
        self.flush()

    def pursued(self, record: Any, frame: int) -> None:
        """A live pursuit frame: truth, estimate and error on the frame timeline."""
        self.current_frame = frame
        self._time()
        truth, estimate = record.truth_world_m, record.estimate_world_m
        if truth is not None:
            self.rec.log("/world/truth", rr.Points3D([truth], radii=0.003, colors=[WHITE]))
        else:
            self.rec.log("/world/truth", rr.Clear(recursive=False))
        for index, cam in enumerate(names.CAMERAS):
            uv = record.uv_px[index]
            if uv is None:
                self.rec.log(f"/world/head/{cam}/features", rr.Clear(recursive=False))
                continue
            self.rec.log(
                f"/world/head/{cam}/features", rr.Points2D([uv], radii=4.0, colors=[GREEN])
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
        self._frame_estimates.append(np.asarray(estimate, float))
        self.rec.log("/world/estimate", rr.Points3D([estimate], radii=0.004, colors=[GREEN]))
        self.rec.log(
            "/world/pursuit/estimates",
            rr.Points3D(np.array(self._frame_estimates), radii=0.0015, colors=[GREEN]),
        )
        if truth is not None:
            error = float(np.linalg.norm(estimate - truth))
            self.rec.log("/world/error", rr.LineStrips3D([[truth, estimate]], colors=[RED]))
            self.rec.log("/measurements/error_mm", rr.Scalars([error * 1000.0]))
            depth = float(np.linalg.norm(truth - self.world_from_head_start[:3, 3]))
            self.rec.log("/measurements/error_pct_of_depth", rr.Scalars([100.0 * error / depth]))

    def calibrated(self, calibration: CalibrationReport) -> None:
        self._time()
        self.rec.log(
            "/results/calibration",
            rr.TextDocument(calibration_markdown(calibration), media_type=rr.MediaType.MARKDOWN),
        )
        self.flush()

    def finished(self, result: RunOutcome) -> None:
        self._time()
        if result.experiment is not None:
            get(self.scenario.experiment.procedure).rows(result.experiment, self)
        text = summary_text(result)
        self.rec.log(
            "/results/summary",
            rr.TextDocument(f"```\n{text}\n```", media_type=rr.MediaType.MARKDOWN),
        )

    # -- the head and its scene -----------------------------------------------------
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
                    colors=[ORANGE, GREY],
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
            rr.TextDocument(scenario_markdown(self.scenario), media_type=rr.MediaType.MARKDOWN),
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
            mjcf_rerun.log_model_geometry(
                self.rec, model, static=self._static_geometry, textured=self.room is not None
            )
        )
        self._body_poses = mjcf_rerun.BodyPoses(model)

    def _pose(self, sim: HeadSim) -> None:
        """The head's pose at this image: kept as rows (with the detections and servo errors), sent by :meth:`_send_kept_rows`."""
        rows, frame, step = self._kept_rows, self.current_frame, self.current_step
        if self._body_poses is not None:
            for path, translation, xyzw in self._body_poses.moved(sim.data):
                rows.add(
                    path, frame, step, rr.Transform3D, translation=translation, quaternion=xyzw
                )
        world_from_head = sim.truth.world_from_head()
        rows.add(
            "/world/head",
            frame,
            step,
            rr.Transform3D,
            translation=world_from_head[:3, 3],
            mat3x3=world_from_head[:3, :3],
        )
        origins, vectors = [], []
        target = self.truth.get(self.label)
        for index, cam in enumerate(names.CAMERAS):
            head_from_camera = sim.truth.head_from_camera(index + 1)
            rows.add(
                f"/world/head/{cam}",
                frame,
                step,
                rr.Transform3D,
                translation=head_from_camera[:3, 3],
                mat3x3=head_from_camera[:3, :3],
            )
            world_from_camera = sim.truth.world_from_camera(index + 1)
            centre = world_from_camera[:3, 3]
            length = 1.0 if target is None else 1.2 * float(np.linalg.norm(target - centre))
            origins.append(centre)
            vectors.append(world_from_camera[:3, 2] * length)
        rows.add(
            "/world/optical_axes",
            frame,
            step,
            rr.Arrows3D,
            instances=2,
            per_row={"show_labels": False},
            origins=origins,
            vectors=vectors,
            colors=[ORANGE, ORANGE],
            labels=["cam1", "cam2"],
        )
        eye = sim.eye_encoder()
        yaw, pitch = sim.neck_encoders()
        for key, value in (("eye_rad", eye), ("neck_yaw_rad", yaw), ("neck_pitch_rad", pitch)):
            rows.add(f"/joints/{key}", frame, step, rr.Scalars, scalars=value)

    # -- the recording's thread ------------------------------------------------------
    def _later(self, log: Callable[..., None], *args: object) -> None:
        """Run ``log(*args)`` on the recording's thread, after what was given before."""
        self._pending = [f for f in self._pending if not f.done() or f.exception() is not None]
        self._pending.append(self._background.submit(log, *args))

    def _send_kept_rows(self) -> None:
        """Send the kept rows, on the recording's thread."""
        if len(self._kept_rows):
            rows, self._kept_rows = self._kept_rows, RowColumns()
            self._later(rows.send, self.rec)

    def _wait(self) -> None:
        """Until the recording's thread did all it was given; its first error is raised."""
        pending, self._pending = self._pending, []
        for future in pending:
            future.result()

    def flush(self, viewer_wait_s: float = VIEWER_WAIT_S) -> None:
        """Everything logged so far written (or streamed: within ``viewer_wait_s``)."""
        self._send_kept_rows()
        self._wait()
        if self.target.connect_url is None:
            self.rec.flush()
            return
        try:
            flush_to_viewer(self.rec, self.target.connect_url, viewer_wait_s)
        except ViewerUnreachable:
            self._viewer_lost = True
            raise

    def close(self) -> None:
        """Flush and write the footer; the file is complete after this."""
        if not self.closed:
            self.closed = True
            flushed = False
            try:
                if not self._viewer_lost:
                    # After Ctrl-C or SIGTERM a viewer gets a moment, not the full wait.
                    self.flush(INTERRUPTED_VIEWER_WAIT_S if interrupted() else VIEWER_WAIT_S)
                    flushed = True
            finally:
                self._background.shutdown(wait=True, cancel_futures=False)
                if flushed or self.target.connect_url is None:
                    self.rec.disconnect()
                    if self.target.connect_url is not None:
                        viewer_stream_closed()
                # Else the stream is left as it is: with a viewer that does not take the data
                # (or after an interrupted flush), disconnecting, even finishing only the file
                # sink, waits for ever.  The file, if any, is then without footer (readable);
                # the command line leaves without waiting for the stream.

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# -- rows sent as columns ---------------------------------------------------------
# The rows logged with every image (poses, joint angles, detections, servo errors) are
# gathered per entity and sent with one ``send_columns`` call per entity instead of one
# ``log`` per row: ``rr.log`` costs about 0.1 ms per Transform3D here, and every image
# logs a dozen of them (half a second of the quick start).  The rows are the same
# (frame and step, the values), so a viewer shows the same recording.


@dataclass
class _Entity:
    """One entity's rows: ``instances`` values of each field per row (None: a list of
    any length per row)."""

    archetype: Any
    instances: int | None
    frames: list[int] = field(default_factory=list)
    lengths: list[int] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)
    fields: dict[str, list[Any]] = field(default_factory=dict)
    #: Fields with one value per row whatever ``instances`` is (e.g. ``show_labels``).
    per_row: dict[str, list[Any]] = field(default_factory=dict)


class RowColumns:
    """Rows kept per entity path until :meth:`send`."""

    def __init__(self) -> None:
        self._entities: dict[str, _Entity] = {}

    def add(
        self,
        path: str,
        frame: int,
        step: int,
        archetype: Any,
        instances: int | None = 1,
        per_row: dict[str, Any] | None = None,
        **values: Any,
    ) -> None:
        """A row of ``archetype`` (``rr.Transform3D``, ``rr.Scalars``, ...) at ``path``:
        ``values`` are the archetype's fields, ``instances`` values each (1: the value
        itself; None: lists of one length, which may be 0: nothing at this row)."""
        entity = self._entities.setdefault(path, _Entity(archetype, instances))
        if entity.archetype is not archetype or entity.instances != instances:
            raise ValueError(f"{path}: rows of one archetype and instance count only")
        if instances != 1:
            lengths = {len(v) for v in values.values()}
            if len(lengths) > 1 or (instances is not None and lengths != {instances}):
                raise ValueError(f"{path}: every field needs {instances or 'the same'} values")
            entity.lengths.append(lengths.pop() if lengths else 0)
        entity.frames.append(frame)
        entity.steps.append(step)
        for name, value in values.items():
            entity.fields.setdefault(name, []).append(value)
        for name, value in (per_row or {}).items():
            entity.per_row.setdefault(name, []).append(value)

    def __len__(self) -> int:
        return sum(len(e.frames) for e in self._entities.values())

    def send(self, rec: rr.RecordingStream) -> None:
        """Send every kept row, an entity per call, and forget them."""
        for path, entity in self._entities.items():
            rows = len(entity.frames)
            if rows == 0:
                continue
            columns = entity.archetype.columns(
                **{name: _column(v, entity.instances) for name, v in entity.fields.items()}
            )
            if entity.instances != 1:
                columns = columns.partition(entity.lengths)
            extra = entity.archetype.columns(**entity.per_row) if entity.per_row else []
            rec.send_columns(
                path,
                indexes=[
                    rr.TimeColumn("frame", sequence=entity.frames),
                    rr.TimeColumn("step", sequence=entity.steps),
                ],
                columns=[*columns, *extra],
            )
        self._entities.clear()


def _column(rows: list[Any], instances: int | None) -> Any:
    """The rows' values end to end: an array, or a list of strings (labels)."""
    flat = list(rows) if instances == 1 else [v for row in rows for v in row]
    return flat if not flat or isinstance(flat[0], str) else np.asarray(flat)


__all__ = ["APP_ID", "FRUSTUM_DEPTH_M", "JPEG_QUALITY", "Recorder", "RowColumns"]
