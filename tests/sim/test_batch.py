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
    BatchSession,
    cuda_available,
    window_intrinsic,
)
from headsim.sim.gl_window import Window
from headsim.sim.settings import HeadSettings, preset
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
    capsys: pytest.CaptureFixture[str],
) -> None:
    with HeadSim() as sim:
        if not cuda_available():
            with pytest.raises(BatchError, match="Warp finds no CUDA device here"):
                BatchRenderer(sim, 1, device="cuda")
            with capsys.disabled():
                print("\nbatch: no CUDA device here; the CUDA render path did not run")
            return
        qpos, classic = _poses(sim, np.array([0.05]))
        images = BatchRenderer(sim, 1, device="cuda").render(qpos)
        found = find_marker(images[0, 0], "red")
        assert found.uv is not None and classic[0][0].uv is not None
        assert np.hypot(*np.subtract(found.uv, classic[0][0].uv)) <= CENTROID_TOLERANCE_PX


def _kx(settings_name: str, kx: float) -> HeadSettings:
    settings = preset(settings_name)
    return replace(settings, cameras=tuple(replace(c, kx=kx, ky=kx) for c in settings.cameras))


def _look(sim: HeadSim, eyes: list[float]) -> list[tuple[float, float]]:
    """The red marker's centroid in Ca1 at each eye angle (one image each)."""
    found = []
    for eye in eyes:
        sim.move(eye=eye)
        uv = find_marker(sim.render(1), "red").uv
        assert uv is not None
        found.append(uv)
    return found


def test_heads_in_lockstep_render_together_and_each_sees_what_it_sees_alone() -> None:
    """Three heads of three focal lengths, a different number of images each: at one sample
    per pixel they share one Warp scene (Warp's per-world camera parameters), the batch
    shrinks as heads finish, and every centroid is the classic renderer's."""
    focals, eyes = (700.0, 835.0, 1000.0), [[0.0, 0.04, 0.08], [0.02, 0.06], [0.05]]
    sims = [HeadSim(settings=_kx("ideal", kx)) for kx in focals]
    classic = [_look(sim, e) for sim, e in zip(sims, eyes, strict=True)]
    for sim in sims:
        sim.close()
    session = BatchSession(samples_per_pixel=1)

    def head(kx: float, angles: list[float]) -> Callable[[], list[tuple[float, float]]]:
        return lambda: _look(HeadSim(settings=_kx("ideal", kx)), angles)

    batch = session.run([head(kx, e) for kx, e in zip(focals, eyes, strict=True)])
    offsets = [
        float(np.hypot(*np.subtract(b, c)))
        for bs, cs in zip(batch, classic, strict=True)
        for b, c in zip(bs, cs, strict=True)
    ]
    assert max(offsets) <= CENTROID_TOLERANCE_PX, offsets
    # The focal length moved the marker: kx 700 and 1000 differ by tens of pixels at eye 0.05.
    assert abs(batch[0][2][0] - batch[2][0][0]) > 5
    stats = session.stats
    # Every head renders in one call per step while it runs: 3 + 2 + 1 images in 3 calls.
    assert (stats.images, stats.calls, stats.largest) == (6, 3, 3), stats
    assert "MuJoCo Warp on cpu: 6 images in 3 batches" in session.describe()


def test_with_sub_pixel_samples_heads_of_two_focal_lengths_still_share_a_call() -> None:
    """Two samples per axis (rays on a grid twice as fine, averaged): the classic renderer's
    supersampling, and each world still casts from its own focal length."""
    focals = (700.0, 900.0)
    classic = []
    for kx in focals:
        with HeadSim(settings=_kx("ideal", kx)) as sim:
            classic.append(_look(sim, [0.03]))
    session = BatchSession(samples_per_pixel=2)
    batch = session.run(
        [lambda kx=kx: _look(HeadSim(settings=_kx("ideal", kx)), [0.03]) for kx in focals]
    )
    assert (session.stats.images, session.stats.calls, session.stats.largest) == (2, 1, 2)
    for (b,), (c,) in zip(batch, classic, strict=True):
        assert np.hypot(*np.subtract(b, c)) <= CENTROID_TOLERANCE_PX


def test_an_error_in_one_head_is_raised_once_the_others_end() -> None:
    session = BatchSession(samples_per_pixel=1)
    ended = []

    def fine() -> None:
        _look(HeadSim(settings=preset("ideal")), [0.0, 0.05])
        ended.append(True)

    def broken() -> None:
        raise RuntimeError("this head broke")

    with pytest.raises(RuntimeError, match="this head broke"):
        session.run([fine, broken])
    assert ended == [True]  # the healthy head was not left waiting for the broken one


def test_bad_sessions_name_what_is_allowed() -> None:
    with pytest.raises(BatchError, match="samples_per_pixel must be a whole number from 1 to 8"):
        BatchSession(samples_per_pixel=0)
    with pytest.raises(BatchError, match="device must be one of cpu, cuda, got 'gpu'"):
        BatchSession(device="gpu")


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


@pytest.mark.parametrize("name", ["ideal", "paper"])
def test_windows_and_previews_are_what_the_classic_renderer_takes(name: str) -> None:
    """Only a window's rays are cast, on a rounded-up size; its marker lies where the
    classic window puts it, and a binned preview finds the marker where the classic one does."""
    with HeadSim(settings=preset(name)) as sim:
        sim.move(eye=0.04)
        full = find_marker(sim.render(1), "red").uv
        assert full is not None
        cam = sim.settings.cameras[0]
        window = Window.around(full, 20.5, (cam.width, cam.height))
        classic = find_marker(sim.render_window(1, window), "red").uv
        preview = find_marker(sim.render_preview(1, 4), "red").uv
        qpos = sim.data.qpos.copy()

    def batch() -> tuple:
        with HeadSim(settings=preset(name)) as head:
            head.data.qpos[:] = qpos
            head.move(eye=0.04)
            return (
                find_marker(head.render_window(1, window), "red").uv,
                find_marker(head.render_preview(1, 4), "red").uv,
                head.rendered_frames,
            )

    session = BatchSession()
    ((win, prev, frames),) = session.run([batch])
    assert win is not None and classic is not None and prev is not None and preview is not None
    assert np.hypot(*np.subtract(win, classic)) <= CENTROID_TOLERANCE_PX
    assert np.hypot(*np.subtract(prev, preview)) <= CENTROID_TOLERANCE_PX
    assert frames < 0.2  # a 41 px window and a 1/16 preview: a small share of one frame


def test_warp_starts_without_a_cuda_warning_on_a_machine_without_the_driver() -> None:
    """Warp's native start-up complains about a missing libcuda; users here asked for no GPU."""
    import ctypes.util
    import subprocess
    import sys

    code = "from headsim.sim.batch import cuda_available; print(cuda_available())"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    if ctypes.util.find_library("cuda") is not None:
        print("\nbatch: a CUDA driver is installed here; the quiet start-up did not run")
        assert done.stdout.strip() in {"True", "False"}
        return
    assert done.stdout.strip() == "False"
    assert "CUDA" not in done.stderr, done.stderr
