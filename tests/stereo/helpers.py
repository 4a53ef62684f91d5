"""The presets, the poses per calibration and a calibration built from the simulator's truth."""

from __future__ import annotations

from headsim.geometry.transforms import invert_transform
from headsim.sim.settings import ideal_head, paper_head
from headsim.sim.simulator import HeadSim
from headsim.stereo.calibration import (
    CameraCalibration,
    StereoCalibration,
)

PRESETS = {"ideal": ideal_head, "paper": paper_head}
#: Poses per calibration in the tests (the benchmark uses more).
TEST_POSES = 12


def calibration_from_truth(sim: HeadSim) -> StereoCalibration:
    cams = [
        CameraCalibration(
            sim.camera_matrix(i),
            sim.dist_coeffs(i),
            0.0,
            sim.camera_matrix(i),
            sim.dist_coeffs(i),
            (sim.camera_settings(i).width, sim.camera_settings(i).height),
        )
        for i in (1, 2)
    ]
    cam2_from_cam1 = invert_transform(sim.world_from_camera(2)) @ sim.world_from_camera(1)
    return StereoCalibration(
        mono1=cams[0],
        mono2=cams[1],
        cam1=cams[0],
        cam2=cams[1],
        stereo_rms_px=0.0,
        cam2_from_cam1=cam2_from_cam1,
        true_cam2_from_cam1=cam2_from_cam1,
        true_head_from_cam1=sim.head_from_camera(1),
        views=0,
        refined=False,
    )
