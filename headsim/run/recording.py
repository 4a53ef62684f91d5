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

The layout and palette are in :mod:`headsim.run.recording_layout`, the head and
scene's logging in :mod:`headsim.run.recording_scene`, the results' in
:mod:`headsim.run.recording_results`; the :class:`Recorder` follows the events.

The stream goes to a file, a running viewer (``--connect``) or a served web
viewer (``--serve``), or several (:class:`headsim.run.rerun_cli.RecordingTarget`).

The stream is written as it goes and flushed after every measurement; it is
closed with its footer when the run ends, also when it is interrupted
(Ctrl-C).  A killed writer leaves a file without footer that the viewer and
``rerun.chunk.RrdReader(...).stream()`` still read (``rerun rrd optimize``
rewrites it).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from datetime import timedelta
from pathlib import Path

import cv2
import numpy as np
import rerun as rr

from headsim.active.events import Detected, FixationStarted, PhaseStarted
from headsim.active.measurement import HeadKnowledge
from headsim.run import mjcf_rerun
from headsim.run.events import CalibrationDone, MeasurementRecorded, RunFinished, Stamp
from headsim.run.recording_columns import RowColumns
from headsim.run.recording_layout import (
    GREEN,
    GREY,
    ORANGE,
    UI_RADIUS_LARGE,
    UI_RADIUS_SMALL,
    WHITE,
    blueprint,
    recording_id,
)
from headsim.run.recording_results import ResultsLogging
from headsim.run.rerun_cli import RecordingTarget
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.sim.events import ImageKind, ImageTaken
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


class Recorder(ResultsLogging):
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
        self._kept_rows = RowColumns()
        # JPEG encoding and sending the kept rows run on one thread beside the run's
        # (OpenCV's encoder lets the renders go on meanwhile), in the order given.
        self._background = ThreadPoolExecutor(1, thread_name_prefix="headsim-recording")
        self._pending = []
        self._log_static()

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
        ok, jpeg = cv2.imencode(
            ".jpg",
            cv2.cvtColor(image, cv2.COLOR_RGB2BGR),
            [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality],
        )
        if ok:
            self.rec.set_time("frame", sequence=frame)
            self.rec.set_time("step", sequence=step)
            self.rec.log(
                f"/world/head/{cam}/image",
                rr.EncodedImage(contents=jpeg.tobytes(), media_type="image/jpeg"),
            )

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

    def close(self) -> None:
        """Flush and write the footer; the file is complete after this."""
        if not self.closed:
            self.closed = True
            try:
                self.flush()
            finally:
                self._background.shutdown(wait=True, cancel_futures=False)
                self.rec.disconnect()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ = ["APP_ID", "JPEG_QUALITY", "Recorder"]
