"""What a recording logs of the head and its scene: the static entities (frusta, goal
lines, series, the scenario's document), each scene's model geometry, and the poses
(head, cameras, optical axes, joints) on the frame and step timelines."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np
import rerun as rr

from headsim.run import mjcf_rerun
from headsim.run.recording_columns import RowColumns
from headsim.run.recording_layout import (
    GREY,
    ORANGE,
)
from headsim.scenario.spec import Scenario
from headsim.sim import names
from headsim.sim.optics import camera_matrix
from headsim.sim.simulator import HeadSim

#: Distance from the image plane to the optical centre of a drawn frustum, m.
FRUSTUM_DEPTH_M = 0.08


class SceneLogging:
    """The head and its scene in a recording; :class:`headsim.run.recording.Recorder` sets the state."""

    rec: rr.RecordingStream
    scenario: Scenario
    current_frame: int
    current_step: int
    label: str
    truth: dict[str, np.ndarray]
    geometry: list[mjcf_rerun.ModelGeometry]
    _scene_key: tuple[str, ...] | None
    _body_poses: mjcf_rerun.BodyPoses | None
    _static_geometry: bool
    _kept_rows: RowColumns
    #: The recording's thread (JPEG encoding, sending kept rows) and what it was given.
    _background: ThreadPoolExecutor
    _pending: list[Future[None]]

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
        """The head's pose at this image: kept as rows (with the detections and servo errors), sent by :meth:`_send_kept_rows`."""
        rows, frame, step = self._kept_rows, self.current_frame, self.current_step
        if self._body_poses is not None:
            for path, translation, xyzw in self._body_poses.moved(sim.data):
                rows.add(
                    path, frame, step, rr.Transform3D, translation=translation, quaternion=xyzw
                )
        world_from_head = sim.world_from_head()
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
            head_from_camera = sim.head_from_camera(index + 1)
            rows.add(
                f"/world/head/{cam}",
                frame,
                step,
                rr.Transform3D,
                translation=head_from_camera[:3, 3],
                mat3x3=head_from_camera[:3, :3],
            )
            world_from_camera = sim.world_from_camera(index + 1)
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

    def flush(self) -> None:
        """Everything logged so far written (or streamed)."""
        self._send_kept_rows()
        self._wait()
        self.rec.flush()


__all__ = ["FRUSTUM_DEPTH_M", "SceneLogging"]
