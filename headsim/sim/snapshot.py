"""One look through both eyes: images, an annotated overview and the ground truth."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cv2
import mujoco
import numpy as np

from headsim.files import write_json_atomic, write_png_atomic
from headsim.sim import names
from headsim.sim.settings import HeadSettings, settings_record
from headsim.sim.simulator import HeadSim
from headsim.version import __version__


def movable_bodies(sim: HeadSim) -> list[str]:
    """Names of the mocap (target) bodies in the scene."""
    model = sim.model
    return [model.body(i).name for i in range(model.nbody) if model.body_mocapid[i] >= 0]


def ground_truth(sim: HeadSim) -> dict[str, Any]:
    """Everything the simulator knows, as JSON-ready data (SI units, OpenCV pixels)."""
    cameras = {}
    targets = {}
    for cam in names.CAMERAS:
        settings = sim.camera_settings(cam)
        cameras[cam] = {
            "K": sim.camera_matrix(cam),
            "dist_coeffs": sim.dist_coeffs(cam),
            "image_size": [settings.width, settings.height],
            "image_centre": list(settings.image_centre),
            "world_from_camera": sim.world_from_camera(cam),
            "head_from_camera": sim.head_from_camera(cam),
            "effective_initial_direction_rad": sim.effective_initial_direction(cam),
        }
    for body in movable_bodies(sim):
        entry: dict[str, Any] = {
            "world_m": sim.position(body),
            "head_m": sim.position(body, "head"),
        }
        for cam in names.CAMERAS:
            p_cam = sim.position(body, cam)
            entry[f"{cam}_m"] = p_cam
            entry[f"{cam}_px"] = sim.project(sim.position(body), cam)[0] if p_cam[2] > 0 else None
        targets[body] = entry
    return {
        "joints_true_rad": sim.true_joint_angles(),
        "eye_encoder_rad": sim.eye_encoder(),
        "eye_encoder_steps": sim.eye_encoder_steps(),
        "neck_encoders_rad": list(sim.neck_encoders()),
        "world_from_head": sim.world_from_head(),
        "cameras": cameras,
        "targets": targets,
    }


def overview(images: list[np.ndarray], truth: dict[str, Any]) -> np.ndarray:
    """Both images side by side with the image centre and true target projections marked."""
    panels = []
    for index, cam in enumerate(names.CAMERAS):
        panel = np.ascontiguousarray(images[index].copy())
        u0, v0 = truth["cameras"][cam]["image_centre"]
        cv2.drawMarker(panel, (round(u0), round(v0)), (255, 255, 255), cv2.MARKER_CROSS, 24, 1)
        for name, entry in truth["targets"].items():
            uv = entry[f"{cam}_px"]
            if uv is None or not (0 <= uv[0] < panel.shape[1] and 0 <= uv[1] < panel.shape[0]):
                continue
            point = (round(uv[0]), round(uv[1]))
            cv2.circle(panel, point, 9, (255, 255, 255), 1, cv2.LINE_AA)
            cv2.putText(
                panel,
                name,
                (point[0] + 11, point[1] - 6),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.4,
                (255, 255, 255),
                1,
                cv2.LINE_AA,
            )
        cv2.putText(
            panel, cam, (8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 0), 1, cv2.LINE_AA
        )
        panels.append(panel)
    height = max(p.shape[0] for p in panels)
    padded = [np.pad(p, ((0, height - p.shape[0]), (0, 4), (0, 0))) for p in panels]
    return np.concatenate(padded, axis=1)


def take_snapshot(
    out_dir: str | Path,
    scene: str = "default",
    settings: HeadSettings | None = None,
    *,
    neck_yaw: float = 0.0,
    neck_pitch: float = 0.0,
    eye: float = 0.0,
) -> dict[str, Path]:
    """Pose the head, render both cameras and write PNGs plus ``truth.json`` to ``out_dir``."""
    out = Path(out_dir)
    with HeadSim(scene, settings) as sim:
        sim.move(neck_yaw=neck_yaw, neck_pitch=neck_pitch, eye=eye)
        images = [sim.render(cam) for cam in names.CAMERAS]
        truth = ground_truth(sim)
        written = {
            cam: write_png_atomic(out / f"{cam}.png", images[i])
            for i, cam in enumerate(names.CAMERAS)
        }
        written["overview"] = write_png_atomic(out / "overview.png", overview(images, truth))
        payload = {
            "headsim_version": __version__,
            "mujoco_version": mujoco.__version__,
            "scene": str(scene),
            "settings": settings_record(sim.settings),
            "command_rad": {"neck_yaw": neck_yaw, "neck_pitch": neck_pitch, "eye": eye},
            "renders": sim.render_count,
            "truth": truth,
        }
        written["truth"] = write_json_atomic(out / "truth.json", payload)
    return written
