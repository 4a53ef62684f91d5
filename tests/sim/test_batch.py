"""The batch renderer (MuJoCo Warp, on the CPU here) against the classic renderer, with real
images: the marker's centroid where the classic render puts it, the lens and noise applied
per world, and its refusals."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.sim.batch import BatchError, BatchRenderer, cuda_available
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
