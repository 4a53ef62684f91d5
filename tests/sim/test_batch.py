"""The batch renderer (MuJoCo Warp, on the CPU here) against the classic renderer, with real
images: the marker's centroid where the classic render puts it, the lens and noise applied
per world, and its refusals."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pytest

from headsim.sim.batch import (
    BatchError,
    BatchRenderer,
    cuda_available,
    window_intrinsic,
)
from headsim.sim.settings import preset
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import find_marker

#: The batch renderer's marker centroid may lie this far from the classic one's, px: two
#: rasterisers (ray casting against OpenGL), both without anti-aliasing here.
CENTROID_TOLERANCE_PX = 0.25


def _poses(sim: HeadSim, eyes: np.ndarray) -> tuple[np.ndarray, list[list]]:
    """Each pose's qpos and the classic renderer's detections of the red marker."""
    qpos, classic = [], []
    for eye in eyes:
        sim.move(eye=float(eye), neck_yaw=0.1 * float(eye))
        qpos.append(sim.data.qpos.copy())
        classic.append([find_marker(sim.render(c), "red") for c in (1, 2)])
    return np.array(qpos), classic


@pytest.mark.parametrize("name", ["ideal", "paper"])
def test_the_marker_lies_where_the_classic_render_puts_it(name: str) -> None:
    """ideal: a pinhole; paper: the paper's distorted lenses, remapped as the classic path."""
    with HeadSim(settings=preset(name)) as sim:
        qpos, classic = _poses(sim, np.linspace(-0.02, 0.1, 6))
        images = BatchRenderer(sim, len(qpos)).render(qpos)
        assert images.shape == (6, 2, 480, 640, 3) and images.dtype == np.uint8
        offsets = []
        for world, pair in enumerate(classic):
            for camera, expected in enumerate(pair):
                found = find_marker(images[world, camera], "red")
                assert found.uv is not None and expected.uv is not None
                offsets.append(float(np.hypot(*np.subtract(found.uv, expected.uv))))
                assert found.area_px == pytest.approx(expected.area_px, rel=0.1)
        assert max(offsets) <= CENTROID_TOLERANCE_PX, offsets
        # The eye turned: the batch images moved as the classic ones did, by many pixels.
        first, last = (find_marker(images[w, 0], "red").uv for w in (0, -1))
        assert first is not None and last is not None and abs(first[0] - last[0]) > 50


def test_each_world_draws_its_own_noise_reproducibly_from_the_seed() -> None:
    settings = preset("ideal")
    noisy = replace(settings, cameras=tuple(replace(c, noise_std=2.0) for c in settings.cameras))
    with HeadSim(settings=noisy) as sim:
        qpos = np.tile(sim.data.qpos, (2, 1))
        first = BatchRenderer(sim, 2).render(qpos)
        again = BatchRenderer(sim, 2).render(qpos)
        assert np.array_equal(first, again)
        assert not np.array_equal(first[0, 0], first[1, 0])  # same pose, another stream
        clean = BatchRenderer(HeadSim(settings=settings), 2).render(qpos)
        spread = first.astype(float) - clean.astype(float)
        assert 1.5 < float(spread.std()) < 2.5


def test_bad_requests_name_what_is_allowed() -> None:
    with HeadSim() as sim:
        with pytest.raises(BatchError, match="nworld must be a whole number >= 1"):
            BatchRenderer(sim, 0)
        with pytest.raises(BatchError, match="device must be one of cpu, cuda"):
            BatchRenderer(sim, 1, device="tpu")
        renderer = BatchRenderer(sim, 2)
        with pytest.raises(BatchError, match=r"qpos must have shape \(2, "):
            renderer.render(np.zeros((3, sim.model.nq)))
        assert renderer.describe() == "MuJoCo Warp on cpu: 2 worlds x 2 cameras"


def test_the_cuda_path_runs_where_warp_finds_a_device_and_is_refused_elsewhere(
    did_not_run: Callable[[str], None],
) -> None:
    with HeadSim() as sim:
        if not cuda_available():
            with pytest.raises(BatchError, match="Warp finds no CUDA device here"):
                BatchRenderer(sim, 1, device="cuda")
            did_not_run("batch: no CUDA device here; the CUDA render path did not run")
            return
        qpos, classic = _poses(sim, np.array([0.05]))
        images = BatchRenderer(sim, 1, device="cuda").render(qpos)
        found = find_marker(images[0, 0], "red")
        assert found.uv is not None and classic[0][0].uv is not None
        assert np.hypot(*np.subtract(found.uv, classic[0][0].uv)) <= CENTROID_TOLERANCE_PX


def test_a_window_camera_covers_exactly_its_rectangle_of_the_canvas() -> None:
    """Exact geometry: the whole canvas gives back the camera; a window's edges are the
    canvas's pixel edges there (rays through the same points at unit depth)."""
    intrinsic = np.array([0.0167, 0.0163, 0.0005, -0.0018])
    sensor = np.array([0.01534, 0.01136])
    canvas = (767, 568)
    whole = window_intrinsic(intrinsic, sensor, canvas, (0.0, 0.0, 767.0, 568.0), canvas)
    assert np.allclose(whole, intrinsic, rtol=1e-6, atol=1e-9)

    def edges(k: np.ndarray, size: tuple[int, int]) -> np.ndarray:
        aspect = size[0] / size[1]
        w, h = (
            (sensor[0], sensor[0] / aspect)
            if aspect > sensor[0] / sensor[1]
            else (
                sensor[1] * aspect,
                sensor[1],
            )
        )
        fx, fy, cx, cy = k
        return np.array(
            [-(w / 2 - cx) / fx, (w / 2 + cx) / fx, (h / 2 - cy) / fy, -(h / 2 + cy) / fy]
        )

    full = edges(intrinsic, canvas)
    x0, y0, x1, y1 = 100.0, 40.0, 196.0, 72.0  # 96 x 32, another aspect than the sensor's
    window = edges(
        window_intrinsic(intrinsic, sensor, canvas, (x0, y0, x1, y1), (96, 32)), (96, 32)
    )
    expected = [
        full[0] + (full[1] - full[0]) * x0 / 767,
        full[0] + (full[1] - full[0]) * x1 / 767,
        full[2] + (full[3] - full[2]) * y0 / 568,
        full[2] + (full[3] - full[2]) * y1 / 568,
    ]
    assert np.allclose(window, expected, rtol=1e-5)


def test_warp_starts_without_a_cuda_warning_on_a_machine_without_the_driver(
    did_not_run: Callable[[str], None],
) -> None:
    """Warp's native start-up complains about a missing libcuda; users here asked for no GPU."""
    import ctypes.util
    import subprocess
    import sys

    code = "from headsim.sim.batch import cuda_available; print(cuda_available())"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    if ctypes.util.find_library("cuda") is not None:
        did_not_run("batch: a CUDA driver is installed here; the quiet start-up did not run")
        assert done.stdout.strip() in {"True", "False"}
        return
    assert done.stdout.strip() == "False"
    assert "CUDA" not in done.stderr, done.stderr
