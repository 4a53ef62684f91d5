"""The lockstep device path (MuJoCo Warp), run here on Warp's CPU device: both eyes of
every head cast in one call from the lockstep batch's pose arrays, the marker where the
classic OpenGL render puts it, and its centroid reduced on the device as the host
computes it from the same pixels.  On a GPU (``device="cuda"``) the same code runs;
without one that path says it did not run."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from headsim.envs.fixate import TARGET_BODY, FixateEnv
from headsim.live.paths import Static
from headsim.lockstep import LockstepHeads
from headsim.lockstep.detect import colour_weight_u8
from headsim.lockstep.warp_eyes import WarpEyes, centroids
from headsim.sim.batch import BatchError, cuda_available
from headsim.vision.markers import find_marker

#: Two rasterisers (ray casting against OpenGL), 2x2 samples each: the marker's centroids
#: may differ this much, px.
CENTROID_TOLERANCE_PX = 0.3


def _stepped_heads(n: int) -> tuple[LockstepHeads, np.ndarray]:
    """``n`` heads of the Gym env's kind, stepped apart, and their OpenGL images."""
    env = FixateEnv()
    heads = LockstepHeads(n, env.base_settings, target_body=TARGET_BODY, prepare=env.prepare_model)
    targets = [Static((0.03 * i - 0.04, 0.8 + 0.1 * i, 0.42)) for i in range(n)]
    ids = np.arange(n)
    heads.reset(ids, [env.base_settings] * n, targets)
    heads.command_velocity(ids, np.tile([0.3, -0.2, 0.5], (n, 1)) * np.linspace(-1, 1, n)[:, None])
    frames = heads.capture(ids)
    return heads, frames.images


def test_warp_casts_every_head_in_one_call_where_opengl_draws_them() -> None:
    heads, opengl = _stepped_heads(3)
    cam = heads.settings(0).cameras[0]
    names = heads.camera_names(0)
    eyes = WarpEyes(heads.model(0), names, (cam.width, cam.height), 3, device="cpu")
    eyes.cast(heads.poses())
    images = eyes.images()
    assert images.shape == (3, 2, cam.height, cam.width, 3) and eyes.calls == 1
    sums = eyes.marker_sums("red")
    device = centroids(sums)
    for world in range(3):
        for camera in range(2):
            classic = find_marker(opengl[world, camera], "red")
            warp = find_marker(images[world, camera], "red")
            assert classic.uv is not None and warp.uv is not None
            offset = np.hypot(*np.subtract(warp.uv, classic.uv))
            assert offset <= CENTROID_TOLERANCE_PX, (world, camera, offset)
            # The device's reduction is the host's over the same pixels.
            weight = colour_weight_u8(images[world, camera][None], "red")[0].astype(float)
            kept = np.where(weight > 0.2 * 255, weight / 255, 0.0)
            vs, us = np.mgrid[: cam.height, : cam.width]
            expected = [kept.sum(), (kept * us).sum(), (kept * vs).sum()]
            # (Each pixel's weight is divided by 255 in float32 on the device.)
            np.testing.assert_allclose(sums[world, camera], expected, rtol=1e-6)
    # The heads looked different ways: the comparison is not of one image three times.
    assert np.ptp(device[:, 0, 0]) > 5
    heads.close()


def test_the_gpu_path_runs_where_warp_finds_cuda_and_says_so_elsewhere(
    did_not_run: Callable[[str], None],
) -> None:
    heads, _ = _stepped_heads(1)
    cam = heads.settings(0).cameras[0]
    names = heads.camera_names(0)
    if not cuda_available():
        did_not_run("lockstep: Warp finds no CUDA device here; the GPU path did not run")
        with pytest.raises(BatchError, match="Warp finds no CUDA device here; allowed: cpu"):
            WarpEyes(heads.model(0), names, (cam.width, cam.height), 1, device="cuda")
        heads.close()
        return
    eyes = WarpEyes(heads.model(0), names, (cam.width, cam.height), 1, device="cuda")
    eyes.cast(heads.poses())
    assert np.isfinite(centroids(eyes.marker_sums("red"))).all()
    heads.close()
