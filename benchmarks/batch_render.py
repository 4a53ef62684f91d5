"""The batch renderer (MuJoCo Warp) against the classic one: marker centroids and images per second.

On the same head and scene, the red marker seen by both eyes over seeded random eye
and neck poses: the distance between the batch image's centroid and the classic
render's (median, 95th percentile, max) for each of Warp's sub-pixel sample counts,
and each renderer's centroid against where the pinhole puts the marker's centre (the
floor that anti-aliasing lowers).  Then images per second of each, as ratios
measured in this run, for several batch sizes and two image sizes (the batch renderer
at one ray per pixel, the classic at its default: 2 x 2 supersampling and 4x MSAA).

    python benchmarks/batch_render.py [--poses 16] [--device cpu] [--json F]
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.files import write_json_atomic
from headsim.sim.batch import BatchRenderer
from headsim.sim.settings import CameraSettings, HeadSettings, preset
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import find_marker


def poses(sim: HeadSim, count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    out = []
    for eye, yaw, pitch in zip(
        rng.uniform(-0.02, 0.1, count),
        rng.uniform(-0.05, 0.05, count),
        rng.uniform(-0.03, 0.03, count),
        strict=True,
    ):
        sim.move(eye=float(eye), neck_yaw=float(yaw), neck_pitch=float(pitch))
        out.append(sim.data.qpos.copy())
    return np.array(out)


def truth_px(sim: HeadSim, camera: int) -> np.ndarray:
    """Where the pinhole (and lens) puts the red marker's centre in ``camera``, px."""
    centre = sim.data.xpos[sim.model.body("marker_red").id]
    return np.asarray(sim.project(np.array([centre]), camera), float).reshape(-1)[:2]


def agreement(
    settings: HeadSettings, count: int, seed: int, samples: tuple[int, ...]
) -> dict[str, Any]:
    import mujoco  # after headsim, which picks MUJOCO_GL

    figures: dict[str, Any] = {}
    with HeadSim(settings=settings) as sim:
        qpos = poses(sim, count, seed)
        classic, truth = [], []
        for q in qpos:
            sim.data.qpos[:] = q
            mujoco.mj_forward(sim.model, sim.data)
            classic.append([find_marker(sim.render(c), "red").uv for c in (1, 2)])
            truth.append([truth_px(sim, c) for c in (1, 2)])
        for spp in samples:
            images = BatchRenderer(sim, count, samples_per_pixel=spp).render(qpos)
            to_classic, to_truth = [], []
            for w in range(count):
                for c in range(2):
                    uv = find_marker(images[w, c], "red").uv
                    if uv is None or classic[w][c] is None:
                        continue
                    to_classic.append(float(np.hypot(*np.subtract(uv, classic[w][c]))))
                    to_truth.append(float(np.hypot(*np.subtract(uv, truth[w][c]))))
            figures[f"spp{spp}"] = {
                "to_classic_px": stats(to_classic),
                "to_truth_px": stats(to_truth),
            }
        classic_truth = [
            float(np.hypot(*np.subtract(classic[w][c], truth[w][c])))
            for w in range(count)
            for c in range(2)
            if classic[w][c] is not None
        ]
        figures["classic_to_truth_px"] = stats(classic_truth)
    return figures


def stats(values: list[float]) -> dict[str, float]:
    v = np.array(values)
    return {
        "n": int(v.size),
        "median": float(np.median(v)),
        "p95": float(np.percentile(v, 95)),
        "max": float(v.max()),
    }


def speed(size: tuple[int, int], worlds: tuple[int, ...], device: str) -> dict[str, Any]:
    width, height = size
    focal = 579.41 * height / 480
    camera = CameraSettings(width=width, height=height, kx=focal, ky=focal)
    settings = HeadSettings(cameras=(camera, camera))
    out: dict[str, Any] = {}
    with HeadSim(settings=settings) as sim:
        sim.render(1)
        start = time.perf_counter()
        for _ in range(20):
            sim.render(1)
            sim.render(2)
        classic_s = (time.perf_counter() - start) / 40
        out["classic_images_per_s"] = 1.0 / classic_s
        for n in worlds:
            renderer = BatchRenderer(sim, n, device=device)
            qpos = np.tile(sim.data.qpos, (n, 1))
            renderer.render(qpos)  # the first call builds the kernels
            start = time.perf_counter()
            for _ in range(3):
                renderer.render(qpos)
            per_batch = (time.perf_counter() - start) / 3
            out[f"batch_{n}"] = {
                "images_per_s": 2 * n / per_batch,
                "over_classic": (2 * n / per_batch) * classic_s,
            }
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=16)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--device", default="cpu", choices=("cpu", "cuda"))
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    figures: dict[str, Any] = {}
    for name in ("ideal", "paper"):
        figures[name] = agreement(preset(name), args.poses, args.seed, (1, 2, 4))
        print(f"== centroid, {name} cameras, {args.poses} poses x 2 eyes (px: median / p95 / max)")
        c = figures[name]["classic_to_truth_px"]
        print(f"  classic vs pinhole: {c['median']:.3f} / {c['p95']:.3f} / {c['max']:.3f}")
        for key, value in figures[name].items():
            if key.startswith("spp"):
                a, t = value["to_classic_px"], value["to_truth_px"]
                print(
                    f"  batch {key:5} vs classic {a['median']:.3f} / {a['p95']:.3f} / {a['max']:.3f};"
                    f" vs pinhole {t['median']:.3f} / {t['p95']:.3f} / {t['max']:.3f}"
                )
    for size in ((640, 480), (128, 96)):
        result = speed(size, (1, 16, 64), args.device)
        figures[f"speed_{size[0]}x{size[1]}"] = result
        print(f"== images per second, {size[0]}x{size[1]}, {args.device}")
        print("  classic: 1.00 (one image at a time)")
        for key, value in result.items():
            if key.startswith("batch_"):
                print(f"  {key:9}: {value['over_classic']:.2f} x classic")
    if args.json:
        write_json_atomic(args.json, figures)


if __name__ == "__main__":
    main()
